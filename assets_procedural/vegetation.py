"""Vegetation: street trees, bushes and hedges made of separate leaf clusters.

Foliage is a set of small low-poly blobs (jittered icospheres) with real gaps between them,
so LiDAR beams and camera rays pass through a crown as they do through a real one; the
label pass covers the whole crown with its convex-hull proxy (:mod:`assets_procedural.proxy`).
"""

from __future__ import annotations

import numpy as np

from generator.geometry import Mesh, icosphere, merge, on_ground, tube

CROWN_BASE_MIN = 2.4  # metres: pedestrians and cars fit under a street tree


def _blob(rng: np.random.Generator, center: np.ndarray, radii: np.ndarray, cls: str, material: str,
          jitter: float = 0.18) -> Mesh:
    """A leaf cluster: an ellipsoid icosphere (80 triangles) with radial noise."""
    m = icosphere(1.0, cls, material, 1)
    r = 1.0 + rng.uniform(-jitter, jitter, len(m.vertices))
    m.vertices = m.vertices * r[:, None] * radii + center
    return m


def _scatter(rng: np.random.Generator, n: int, radii: np.ndarray, min_gap: float,
             shell: float = 0.35) -> np.ndarray:
    """(<=n, 3) float: points in the unit-ellipsoid of ``radii`` at least ``min_gap`` apart.

    Points are biased toward the outer shell (``shell`` = inner radius fraction) like the
    foliage of a real crown, leaving its core open.
    """
    pts: list[np.ndarray] = []
    for _ in range(40 * n):
        if len(pts) == n:
            break
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        p = d * rng.uniform(shell, 1.0) ** (1 / 3) * radii
        if all(np.linalg.norm(p - q) >= min_gap for q in pts):
            pts.append(p)
    return np.array(pts).reshape(-1, 3)


CROWN_SHAPES = {
    # name: (crown width / height ratio range, crown base as a fraction of the tree height)
    "round": ((0.85, 1.15), 0.30),
    "oval": ((0.55, 0.75), 0.28),
    "broad": ((1.2, 1.45), 0.35),
}


def tree(rng: np.random.Generator, height: float, shape: str | None = None) -> Mesh:
    """A deciduous street tree ``height`` metres tall.

    Parameters
    ----------
    rng : numpy.random.Generator
    height : float
        Top of the crown above the ground, metres (3-30).
    shape : {"round", "oval", "broad"}, optional
        Crown silhouette; drawn from the rng when omitted.

    Returns
    -------
    Mesh
        Trunk and 3-5 branches (class ``tree_trunk``, material ``bark``) and 16-28 leaf
        clusters (class ``tree_crown``, ``leaves``) with open gaps between them. The crown
        base is at least 2.4 m above the ground.
    """
    if not 3.0 <= height <= 30.0:
        raise ValueError(f"tree height must be in [3, 30] m, got {height}")
    if shape is None:
        shape = str(rng.choice(sorted(CROWN_SHAPES)))
    ratio, base_frac = CROWN_SHAPES[shape]
    base = max(CROWN_BASE_MIN, base_frac * height * rng.uniform(0.9, 1.1))
    crown_h = height - base
    rz = crown_h / 2
    rxy = min(rz * rng.uniform(*ratio), 0.45 * height)
    centre = np.array([0.0, 0.0, base + rz])
    cluster_r = np.clip(0.13 * (rxy + rz), 0.3, 1.1)
    n = int(rng.integers(18, 27))
    # clusters are ellipsoids of radius ~cluster_r; keep centres well apart for gaps
    inner = np.array([rxy, rxy, rz]) - cluster_r * np.array([1.0, 1.0, 1.0])
    inner = np.maximum(inner, 0.3)
    pts = _scatter(rng, n - 1, inner, 1.8 * cluster_r)
    pts = np.concatenate([pts, [[0.0, 0.0, inner[2]]]]) + centre   # one cluster crowns the top
    trunk_r = float(np.clip(0.022 * height, 0.1, 0.4) * rng.uniform(0.85, 1.15))
    top = centre[2] + 0.2 * rz
    parts = [tube((0, 0, 0), (rng.normal(0, 0.05), rng.normal(0, 0.05), top), trunk_r * 1.25, "tree_trunk",
                  "bark", radius1=trunk_r * 0.45, sections=8)]
    # main branches from the crown base toward the upper clusters
    n_br = int(rng.integers(3, 6))
    for i in rng.permutation(len(pts))[:n_br]:
        tip = pts[i] * np.array([0.8, 0.8, 1.0])
        start = np.array([0.0, 0.0, base + rng.uniform(0.0, 0.35) * rz])
        parts.append(tube(start, tip, trunk_r * 0.45, "tree_trunk", "bark", radius1=trunk_r * 0.15, sections=5))
    for p in pts:
        radii = cluster_r * rng.uniform(0.8, 1.15, 3) * np.array([1.0, 1.0, 0.65])
        parts.append(_blob(rng, p, radii, "tree_crown", "leaves"))
    mesh = on_ground(merge(parts))
    # stretch everything above the crown base so the top of the crown is exactly ``height``
    z = mesh.vertices[:, 2]
    k = (height - base) / (z.max() - base)
    mesh.vertices[:, 2] = np.where(z > base, base + (z - base) * k, z)
    return mesh


def bush(rng: np.random.Generator, size: float) -> Mesh:
    """A bush about ``size`` metres across (0.3-3 m), about 0.75 * size high.

    Returns
    -------
    Mesh
        5-8 clumped leaf clusters (class ``vegetation``, material ``hedge_leaves``) with
        small gaps between them, resting on the ground.
    """
    if not 0.3 <= size <= 3.0:
        raise ValueError(f"bush size must be in [0.3, 3] m, got {size}")
    n = int(rng.integers(5, 9))
    r = 0.26 * size
    half = np.array([size / 2 - r, size / 2 - r, 0.75 * size / 2 - r * 0.8])
    pts = _scatter(rng, n, half, 0.75 * r, shell=0.0)
    pts[:, 2] = np.maximum(pts[:, 2], -0.3 * half[2])
    parts = [_blob(rng, p + [0, 0, 0.375 * size], r * rng.uniform(0.8, 1.1, 3) * [1, 1, 0.85], "vegetation",
                   "hedge_leaves", 0.15) for p in pts]
    return on_ground(merge(parts))


def hedge(rng: np.random.Generator, length: float, height: float = 1.2, depth: float = 0.8) -> Mesh:
    """A clipped hedge along x from ``-length / 2`` to ``+length / 2``.

    Parameters
    ----------
    length, height, depth : float
        Metres; depth is the extent along y.

    Returns
    -------
    Mesh
        A row of overlapping box-like clumps, 0.45-0.6 m apart, with small gaps at their
        tops and sides (class ``vegetation``, material ``hedge_leaves``). The clumps are
        clipped to exactly [-length/2, length/2] in x.
    """
    if not (length >= 0.5 and 0.3 <= height <= 4.0 and 0.2 <= depth <= 3.0):
        raise ValueError(f"hedge needs length >= 0.5, height in [0.3, 4], depth in [0.2, 3] m; "
                         f"got {length}, {height}, {depth}")
    spacing = float(rng.uniform(0.45, 0.6))
    n = max(1, int(round(length / spacing)))
    rx = length / n / 2
    xs = -length / 2 + rx + np.arange(n) * 2 * rx
    parts = []
    for x in xs:
        radii = np.array([rx * rng.uniform(1.1, 1.3), depth / 2 * rng.uniform(0.9, 1.0),
                          height / 2 * rng.uniform(0.92, 1.0)])
        c = np.array([x + rng.uniform(-0.05, 0.05) * rx, rng.uniform(-0.04, 0.04) * depth, radii[2]])
        m = _blob(rng, c, radii, "vegetation", "hedge_leaves", 0.12)
        # clipped hedges are boxy: push the blob toward its bounding box (superellipsoid look)
        rel = (m.vertices - c) / radii
        m.vertices = c + np.sign(rel) * np.abs(rel) ** 0.6 * radii
        # squeeze the end clumps along x so the hedge spans exactly [-length/2, length/2]
        reach = np.abs(m.vertices[:, 0] - c[0]).max()
        room = length / 2 - abs(c[0])
        if reach > room:
            m.vertices[:, 0] = c[0] + (m.vertices[:, 0] - c[0]) * (room / reach)
        parts.append(m)
    out = on_ground(merge(parts))
    return out
