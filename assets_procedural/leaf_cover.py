"""Leaf cover: a skin of separate small leaf triangles over a clipped body (hedges, topiary).

A clipped hedge is not a surface but thousands of small leaves, each facing out at its own angle
a few centimetres in front of or behind its neighbours, with dark holes between them where the
eye (and a LiDAR beam) reaches into the shaded inside. :func:`leaf_cover` scatters such leaves
over the outside of a body made of overlapping clumps: area-weighted on the clumps' faces,
skipping faces buried inside a neighbouring clump and the underside, each leaf tilted off the
local surface and set in or out by a few centimetres. Leaves are triangles (each its own three
vertices, so the shaders' "Random Per Island" shades leaf by leaf), real geometry that the
LiDAR casts against.
"""

from __future__ import annotations

import numpy as np

from generator.geometry import Mesh, cross, face_normals, unit
from generator.geometry.primitives import resolve_ids

#: Leaves per square metre of hedge face; leaf length range (m); half-width / length;
#: how far a leaf sits out of (+) or into (-) the body's face (m); tilt of a leaf off the face (0 flat).
DENSITY, LENGTH, WIDTH, DEPTH, TILT = 160.0, (0.08, 0.14), 0.4, (0.0, 0.06), 0.5


def outside(points: np.ndarray, owner: np.ndarray, centres: np.ndarray, radii: np.ndarray,
            power: float, margin: float = 0.92) -> np.ndarray:
    """(n,) bool: ``points`` (n, 3) not inside any clump but their ``owner`` (n,) one.

    A clump is the superellipsoid ``sum(|(p - centre) / radii| ** power) < 1`` (``centres``,
    ``radii`` (c, 3)); ``margin`` < 1 shrinks it a little so a point on a seam between two
    clumps still counts as outside.
    """
    keep = np.ones(len(points), bool)
    # which points fall in a clump's x extent is a matter of value, not of order among equal x: any sort
    # gives the same sets (numpy's default one is ~4x faster than the stable one here)
    order = np.argsort(points[:, 0])
    xs = points[order, 0]
    for j in range(len(centres)):      # only the points within the clump's x extent can be inside it
        lo, hi = np.searchsorted(xs, [centres[j, 0] - radii[j, 0], centres[j, 0] + radii[j, 0]], side="left")
        i = order[lo:hi]
        q = np.abs((points[i] - centres[j]) / radii[j]) ** power
        keep[i] &= (q.sum(1) >= margin) | (owner[i] == j)
    return keep


def leaf_cover(rng: np.random.Generator, body: Mesh, owner: np.ndarray, centres: np.ndarray, radii: np.ndarray,
               power: float, cls: str, material: str, floor: float = 0.0, density: float | None = None) -> Mesh:
    """Separate leaf triangles scattered over the outside of ``body``.

    Parameters
    ----------
    rng : numpy.random.Generator
    body : Mesh
        Overlapping clumps; ``owner`` (m,) int gives each face's clump, ``centres`` and ``radii``
        (c, 3) each clump's superellipsoid (exponent ``power``, :func:`outside`).
    cls, material : str
        Class and material of every leaf.
    floor : float
        No leaf is rooted below this height (the hedge's foot stays bare and gappy).
    density : float, optional
        Leaves per square metre of the body's outer faces (default :data:`DENSITY`).

    Returns
    -------
    Mesh
        About ``density`` * (outer, upward-or-sideways face area) triangles, each its own island.
    """
    density = DENSITY if density is None else density
    tri = body.vertices[body.faces]
    n = face_normals(body)
    area = 0.5 * np.linalg.norm(cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    area = np.where(n[:, 2] > -0.5, area, 0.0)                       # not the underside
    count = int(rng.poisson(density * area.sum()))
    face = rng.choice(len(area), count, p=area / area.sum()) if count else np.zeros(0, int)
    a, b = rng.random((2, count))
    flip = a + b > 1.0
    a, b = np.where(flip, 1.0 - a, a), np.where(flip, 1.0 - b, b)
    t = tri[face]
    p = t[:, 0] + a[:, None] * (t[:, 1] - t[:, 0]) + b[:, None] * (t[:, 2] - t[:, 0])
    up = unit(n[face] + TILT * rng.normal(size=(count, 3)))         # each leaf faces out at its own angle
    p = p + n[face] * rng.uniform(*DEPTH, (count, 1))
    keep = outside(p, owner[face], centres, radii, power) & (p[:, 2] > floor)
    p, up = p[keep], up[keep]
    m = len(p)
    axis = unit(cross(up, rng.normal(size=(m, 3))))               # the blade's direction in its plane
    across = cross(up, axis)
    length = rng.uniform(*LENGTH, (m, 1))
    base = p - 0.45 * length * axis                                   # the leaf's middle on the sample point
    w = WIDTH * length * rng.uniform(0.8, 1.2, (m, 1))
    v = np.stack([base + 0.25 * length * axis - w * across, base + length * axis + 0.15 * length * up,
                  base + 0.25 * length * axis + w * across], 1)
    cid, mid = resolve_ids(cls, material)
    return Mesh(v.reshape(-1, 3), np.arange(3 * m, dtype=np.int64).reshape(m, 3), cid, mid)
