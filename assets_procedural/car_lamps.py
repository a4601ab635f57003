"""A car's lamps as lenses on its shell: strips that follow the body round the corners of nose and tail.

Each lens is a ruled strip of quads a few millimetres proud of the lofted shell
(:func:`assets_procedural.car_body.body_shell`): across the flat end cap from its inner end to the
corner, then back along the side (the wrap), narrowing as it goes, as modern lamps sweep round
the wing. The strip's lower and upper edges each follow the shell at their own height, so the lens
hugs the body instead of standing off it like a box; a rim closes it to the shell. About 24 triangles a lamp.

Local frame as :mod:`assets_procedural.vehicle`: +x forward, +y left, z up.
"""

from __future__ import annotations

import numpy as np

from generator.geometry import Mesh, cross, merge, quads

LENS_M = 0.02    #: metres a lens stands out of the shell (>= 2 cm: no z-fighting), closed by a rim


def surface_y(info: dict, x: np.ndarray, z: np.ndarray) -> np.ndarray:
    """|y| (metres) of the shell's side at (``x``, ``z``): each section's +y half (points 0-7, bottom to
    crown) read at ``z``, then linear between the sections (as the loft is)."""
    rings, xs = info["rings"], info["xs"]
    x, z = np.broadcast_arrays(np.asarray(x, float), np.asarray(z, float))
    out = np.empty(x.shape)
    for i, (xx, zz) in enumerate(zip(x.ravel(), z.ravel(), strict=True)):
        k = int(np.clip(np.searchsorted(xs, xx) - 1, 0, len(xs) - 2))
        t = (xx - xs[k]) / max(xs[k + 1] - xs[k], 1e-9)
        y0 = np.interp(zz, rings[k, :8, 2], rings[k, :8, 1])
        y1 = np.interp(zz, rings[k + 1, :8, 2], rings[k + 1, :8, 1])
        out.flat[i] = (1 - t) * y0 + t * y1
    return out


def lamp(info: dict, front: bool, y_in: float, z_lo: float, z_hi: float, wrap: float, material: str,
         cls: str = "car") -> Mesh:
    """The pair of lenses at one end of the car (both sides).

    Parameters
    ----------
    info : dict
        The landmarks of :func:`assets_procedural.car_body.body_shell` (``xs``, ``rings``).
    front : bool
        The nose (+x end) or the tail.
    y_in : float
        |y| of the lens's inner end on the end cap, metres.
    z_lo, z_hi : float
        Heights of its lower and upper edge on the end cap; they close in towards the wrap's end
        (to 35 % of the height there, about the middle).
    wrap : float
        How far the lens reaches back along the side, metres.
    material : str
        ``headlight`` or ``taillight``.
    """
    xs = info["xs"]
    x_end, sgn = (xs[-1], 1.0) if front else (xs[0], -1.0)
    # along the lens: on the cap (inner end, corner), then sections back along the side
    d = np.array([0.0, 0.0, *[v for v in sgn * (x_end - xs) if 0.0 < v <= wrap + 1e-9]])
    if d[-1] < wrap - 0.02:
        d = np.append(d, wrap)
    x = x_end - sgn * d
    f = d / max(d[-1], 1e-9)                                  # 0 on the cap .. 1 at the wrap's end
    zc = 0.5 * (z_lo + z_hi)
    lo, hi = zc - (zc - z_lo) * (1 - 0.65 * f), zc + (z_hi - zc) * (1 - 0.65 * f)
    y_lo, y_hi = surface_y(info, x, lo), surface_y(info, x, hi)
    y_lo[0] = y_hi[0] = y_in
    on_cap = d <= 1e-9
    shell_lo, shell_hi = np.stack([x, y_lo, lo], 1), np.stack([x, y_hi, hi], 1)
    # the lens stands out of the shell: along x on the cap, across y on the side
    out = np.where(on_cap[:, None], [sgn * LENS_M, 0.0, 0.0], [0.0, LENS_M, 0.0])
    lens_lo, lens_hi = shell_lo + out, shell_hi + out
    ref = np.array([x_end - sgn * 1.0, 0.0, zc])               # a point inside the car: faces look away from it
    face = np.stack([lens_lo[:-1], lens_lo[1:], lens_hi[1:], lens_hi[:-1]], 1)
    below = np.stack([shell_lo[:-1], shell_lo[1:], lens_lo[1:], lens_lo[:-1]], 1)    # the lens's rim
    above = np.stack([lens_hi[:-1], lens_hi[1:], shell_hi[1:], shell_hi[:-1]], 1)
    ends = np.stack([np.stack([shell_lo[i], lens_lo[i], lens_hi[i], shell_hi[i]]) for i in (0, -1)])
    corners = np.concatenate([face, below, above, ends])
    normal = cross(corners[:, 1] - corners[:, 0], corners[:, 3] - corners[:, 0])
    normal[len(face):len(face) + len(below)] = [0.0, 0.0, -1.0]
    normal[len(face) + len(below):-2] = [0.0, 0.0, 1.0]
    normal[-2:] = [[0.0, -1.0, 0.0], [-sgn, 0.0, 0.0]]
    normal[:len(face)] *= np.sign(np.einsum("ij,ij->i", normal[:len(face)], face.mean(1) - ref))[:, None]
    mirror = corners * np.array([1.0, -1.0, 1.0])
    return merge([quads(corners, cls, material, normal), quads(mirror, cls, material, normal * [1.0, -1.0, 1.0])])
