"""Fences along x: posts, rails and bars, pickets or wire-mesh panels with real gaps.

Every face is class ``fence``. The gaps are open space in the geometry: LiDAR beams pass
between bars as they do in the real world, while the label pass covers the whole fence
with its convex-hull proxy.
"""

from __future__ import annotations

import numpy as np

from generator.geometry import Mesh, merge, pose, prism
from generator.geometry.primitives import _UNIT_BOX_FACES as _BOX_FACES
from generator.geometry.primitives import resolve_ids

CLS = "fence"


_UNIT = np.array([[0, 0, 0], [0, 0, 1], [0, 1, 0], [0, 1, 1], [1, 0, 0], [1, 0, 1], [1, 1, 0], [1, 1, 1]], float) - 0.5


class _Parts:
    """A fence's parts in order. Runs of bars (and of identical pickets) are built in one batch with
    the same arithmetic per piece as :func:`_bar` / :meth:`Mesh.transformed` one at a time, so the
    merged mesh has the same bytes; a fence has hundreds of bars."""

    def __init__(self, material: str):
        self.material = material
        self.rows: list[tuple[float, ...]] = []
        self.pieces: list[Mesh] = []

    def bar(self, x0: float, x1: float, y0: float, y1: float, z0: float, z1: float, ends: bool = True) -> None:
        self.rows.append((x0, x1, y0, y1, z0, z1, ends))

    def moved(self, mesh: Mesh, transforms: list[np.ndarray]) -> None:
        """``mesh`` under each rigid transform (all with the same rotation), in order."""
        self._flush()
        if not transforms:
            return
        rotated = mesh.vertices @ transforms[0][:3, :3].T
        n = len(mesh.vertices)
        self.pieces.append(Mesh(np.concatenate([rotated + T[:3, 3] for T in transforms]),
                                np.concatenate([mesh.faces + n * i for i in range(len(transforms))]),
                                np.tile(mesh.face_class, len(transforms)),
                                np.tile(mesh.face_material, len(transforms))))

    def _flush(self) -> None:
        if not self.rows:
            return
        r = np.array(self.rows, float)
        self.rows = []
        size = np.stack([r[:, 1] - r[:, 0], r[:, 3] - r[:, 2], r[:, 5] - r[:, 4]], 1)
        center = np.stack([(r[:, 0] + r[:, 1]) / 2, (r[:, 2] + r[:, 3]) / 2, (r[:, 4] + r[:, 5]) / 2], 1)
        local = _UNIT[None] * size[:, None, :]
        verts = local + center[:, None, :]
        faces = _BOX_FACES
        keep = np.ones((len(r), len(faces)), bool)
        bottom = r[:, 4] > 0  # no bottom face on the ground (as box(bottom=z0 > 0))
        cz = local[:, faces].mean(2)[..., 2]
        keep &= bottom[:, None] | (cz > -size[:, 2:3] / 2 + 1e-9)
        cut = r[:, 6] == 0  # ends=False: drop the faces across the longest axis
        if cut.any():
            axis = np.argmax(size, 1)
            c = verts[:, faces].mean(2)
            rel = np.take_along_axis(c, axis[:, None, None].repeat(len(faces), 1), 2)[..., 0] \
                - np.take_along_axis(center * 2, axis[:, None], 1) / 2
            half = np.take_along_axis(size, axis[:, None], 1) / 2
            keep &= ~cut[:, None] | (np.abs(rel) < half - 1e-9)
        idx = np.nonzero(keep)
        cls, mat = resolve_ids(CLS, self.material)
        self.pieces.append(Mesh(verts.reshape(-1, 3), faces[idx[1]] + 8 * idx[0][:, None], cls, mat))

    def mesh(self) -> Mesh:
        self._flush()
        return merge(self.pieces)


def _bars_between(xa: float, xb: float, pitch: float, width: float) -> np.ndarray:
    """(n,) float: centres of bars of ``width`` filling (xa, xb) at about ``pitch`` spacing."""
    span = xb - xa
    n = max(1, int(round(span / pitch)) - 1)
    return xa + span * (np.arange(1, n + 1) / (n + 1))


def _posts(rng: np.random.Generator, length: float, spacing: tuple[float, float], post_w: float) -> np.ndarray:
    """(k,) float: post centres from -length/2 to +length/2, the end posts flush with the ends."""
    half = length / 2 - post_w / 2
    n = max(1, int(np.ceil(2 * half / rng.uniform(*spacing))))
    return np.linspace(-half, half, n + 1)


def _bars(rng: np.random.Generator, length: float, height: float) -> Mesh:
    """Metal railing: square posts, top and bottom rails, vertical bars 10-13 cm apart."""
    mat, pw, bw = "fence_metal", float(rng.uniform(0.05, 0.08)), float(rng.uniform(0.016, 0.025))
    pitch = float(rng.uniform(0.12, 0.15))
    posts = _posts(rng, length, (2.0, 2.6), pw)
    parts = _Parts(mat)
    for x in posts:
        parts.bar(x - pw / 2, x + pw / 2, -pw / 2, pw / 2, 0.0, height)
    for xa, xb in zip(posts[:-1], posts[1:], strict=False):
        for z in (0.12, height - 0.12):
            parts.bar(xa, xb, -0.02, 0.02, z - 0.02, z + 0.02, ends=False)
        for x in _bars_between(xa + pw / 2, xb - pw / 2, pitch, bw):
            parts.bar(x - bw / 2, x + bw / 2, -bw / 2, bw / 2, 0.05, height - 0.03)
    return parts.mesh()


def _pickets(rng: np.random.Generator, length: float, height: float) -> Mesh:
    """Wooden picket fence: posts, two rails behind, pointed pickets with 5-8 cm gaps."""
    mat, pw, kw, kt = "fence_wood", 0.09, float(rng.uniform(0.07, 0.1)), 0.02
    gap = float(rng.uniform(0.05, 0.08))
    posts = _posts(rng, length, (1.8, 2.4), pw)
    parts = _Parts(mat)
    for x in posts:
        parts.bar(x - pw / 2, x + pw / 2, -pw / 2, pw / 2, 0.0, height - 0.05)
    tip = min(0.08, kw * 0.8)
    outline = np.array([[-kw / 2, 0.0], [kw / 2, 0.0], [kw / 2, height - 0.05 - tip], [0.0, height - 0.05],
                        [-kw / 2, height - 0.05 - tip]])
    # picket outline in the x-z plane, extruded along y (roll +90 deg: prism z -> -y)
    picket = prism(outline, -pw / 2 - 0.007 - kt, -pw / 2 - 0.007, CLS, mat, bottom=True)
    for xa, xb in zip(posts[:-1], posts[1:], strict=False):
        for z in (0.3, height - 0.35):
            parts.bar(xa, xb, pw / 2 - 0.035, pw / 2 + 0.005, z - 0.04, z + 0.04, ends=False)
        parts.moved(picket, [pose(x, 0.0, 0.05, roll=np.pi / 2) for x in _bars_between(xa + pw / 2, xb - pw / 2,
                                                                                        kw + gap, kw)])
    return parts.mesh()


def _panels(rng: np.random.Generator, length: float, height: float) -> Mesh:
    """Welded wire-mesh panels (as on school and garden fences): posts, framed 5 mm grid."""
    mat, pw, wire = "fence_metal", float(rng.uniform(0.05, 0.07)), float(rng.uniform(0.005, 0.007))
    cell_x = float(rng.choice([0.1, 0.2]))
    cell_z = 0.2 if cell_x == 0.1 else 0.05 * 4
    posts = _posts(rng, length, (2.4, 2.6), pw)
    parts = _Parts(mat)
    for x in posts:
        parts.bar(x - pw / 2, x + pw / 2, -pw / 2, pw / 2, 0.0, height + 0.05)
    z0, z1 = 0.06, height
    for xa, xb in zip(posts[:-1], posts[1:], strict=False):
        xa, xb = xa + pw / 2, xb - pw / 2
        for x in _bars_between(xa, xb, cell_x, wire):
            parts.bar(x - wire / 2, x + wire / 2, -wire / 2, wire / 2, z0, z1, ends=False)
        nz = max(2, int(round((z1 - z0) / cell_z)) + 1)
        for z in np.linspace(z0 + wire, z1 - wire, nz):
            parts.bar(xa - 0.02, xb + 0.02, wire / 2 + 0.001, 1.5 * wire + 0.001, z - wire / 2, z + wire / 2,
                      ends=False)
    return parts.mesh()


STYLES = {"bars": _bars, "pickets": _pickets, "panels": _panels}


def fence(rng: np.random.Generator, length: float, height: float = 1.5, style: str = "bars") -> Mesh:
    """A fence along x from ``-length / 2`` to ``+length / 2``, centred on y = 0.

    Parameters
    ----------
    length : float
        Metres (>= 0.5).
    height : float
        Top of the posts, metres (0.5-3).
    style : {"bars", "pickets", "panels"}
        Metal railing, wooden picket fence or welded wire-mesh panels.

    Returns
    -------
    Mesh
        Class ``fence``, material ``fence_metal`` or ``fence_wood``; open gaps between bars.
    """
    if style not in STYLES:
        raise ValueError(f"fence style must be one of {sorted(STYLES)}, got {style!r}")
    if not (length >= 0.5 and 0.5 <= height <= 3.0):
        raise ValueError(f"fence needs length >= 0.5 and height in [0.5, 3] m, got {length}, {height}")
    return STYLES[style](rng, length, height)
