"""Bushes and hedges: shaded leaf-cluster bodies under a skin of separate leaf triangles.

A bush is a few clusters (:func:`assets_procedural.foliage.cores`) with gaps between them; a
hedge is a row of boxy clipped clumps (:func:`hedge_body`) stretched along the hedge into one
clipped wall. Both carry a leaf skin (:func:`assets_procedural.leaf_cover.leaf_cover`) on their
outside, so a close look shows leaves, and LiDAR beams end on leaves at varied depths or pass
between clusters; the label pass covers each with its convex-hull proxy (:mod:`generator.geometry.proxy`).
"""

from __future__ import annotations

import numpy as np

from assets_procedural import foliage
from assets_procedural.leaf_cover import leaf_cover
from generator.geometry import Mesh, icosphere, merge, on_ground
from generator.materials import material_table

#: The hedge clumps' stretch along x (more overlap: one clipped wall rather than a row of barrels;
#: beams still pass low between their rounded feet).
HEDGE_STRETCH = 1.3
#: A bush cluster's core / its radius: its leaf skin then reaches about the cluster's radius (the bush is
#: ``size`` across; a 20-triangle core's faces lie at 0.8 of its vertices' radius).
BUSH_CORE = 1.1
_ICO1 = 42      #: vertices of a once-subdivided icosphere (one hedge clump)


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


def bush(rng: np.random.Generator, size: float) -> Mesh:
    """A bush about ``size`` metres across (0.3-3 m), about 0.75 * size high.

    Returns
    -------
    Mesh
        5-8 leaf clusters (class ``vegetation``): each a 20-triangle core (material
        ``leaf_shade``) under a skin of separate small leaves
        (:func:`assets_procedural.leaf_cover.leaf_cover`, material ``hedge_leaves``), with gaps
        between clusters, resting on the ground.
    """
    if not 0.3 <= size <= 3.0:
        raise ValueError(f"bush size must be in [0.3, 3] m, got {size}")
    n = int(rng.integers(5, 9))
    r = 0.26 * size
    half = np.array([size / 2 - r, size / 2 - r, 0.75 * size / 2 - r * 0.8])
    pts = _scatter(rng, n, half, 0.75 * r, shell=0.0)
    pts[:, 2] = np.maximum(pts[:, 2], -0.3 * half[2])
    centres = pts + [0, 0, 0.375 * size]
    radii = r * rng.uniform(0.8, 1.1, (len(centres), 3)) * [1, 1, 0.85]
    core = foliage.cores(rng, centres, BUSH_CORE * radii, "vegetation", "leaf_shade")
    owner = np.arange(core.n_faces) // (core.n_faces // len(centres))   # each core's faces in a block
    leaves = leaf_cover(rng, core, owner, centres, BUSH_CORE * radii, 2.0, "vegetation", "hedge_leaves",
                        float(core.vertices[:, 2].min()) + 0.1 * size)
    return on_ground(merge([core, leaves]))


def hedge(rng: np.random.Generator, length: float, height: float = 1.2, depth: float = 0.8) -> Mesh:
    """A clipped hedge along x from ``-length / 2`` to ``+length / 2``, with leaves.

    Parameters
    ----------
    length, height, depth : float
        Metres; depth is the extent along y.

    Returns
    -------
    Mesh
        :func:`hedge_body` (material ``hedge_body``: the shaded inside, packed leaves in the shader)
        with each clump stretched to :data:`HEDGE_STRETCH` along x (overlapping more), under a skin of
        separate small leaves (:func:`assets_procedural.leaf_cover.leaf_cover`, material
        ``hedge_leaves``) on its sides and top, clipped 3 cm outside the body, all class ``vegetation``,
        within [-length/2, length/2] in x.
    """
    body = hedge_body(rng, length, height, depth)
    v = body.vertices.reshape(-1, _ICO1, 3)
    centres = v.mean(1)
    v = v.copy()
    dx = v[..., 0] - centres[:, None, 0]
    room = (length / 2 - np.abs(centres[:, 0])) / np.maximum(np.abs(dx).max(1), 1e-9)
    v[..., 0] = centres[:, None, 0] + dx * np.minimum(HEDGE_STRETCH, np.maximum(room, 1.0))[:, None]
    body.vertices = v.reshape(-1, 3)
    radii = np.ptp(v, 1) / 2
    body.face_material = np.full(body.n_faces, material_table().id("hedge_body"), body.face_material.dtype)
    owner = np.arange(body.n_faces) // (body.n_faces // len(centres))
    leaves = leaf_cover(rng, body, owner, centres, radii, 2 / 0.6, "vegetation", "hedge_leaves", 0.15 * height)
    # clipped: a leaf reaching past the shears' planes (3 cm outside the body) is cut back toward its base
    lo = np.array([-length / 2, body.vertices[:, 1].min() - 0.03, 0.0])
    hi = np.array([length / 2, body.vertices[:, 1].max() + 0.03, body.vertices[:, 2].max() + 0.03])
    return merge([body, _cut_back(leaves, lo, hi)])


def _cut_back(leaves: Mesh, lo: np.ndarray, hi: np.ndarray) -> Mesh:
    """``leaves`` (separate triangles: side, tip, side) shortened toward the middle of their base edge
    until inside the box [``lo``, ``hi``] (3,); leaves whose base lies outside, or that would keep less
    than 30 % of their size (slivers), are dropped."""
    t = leaves.vertices[leaves.faces]                                       # (n, 3, 3)
    base = (t[:, 0] + t[:, 2]) / 2
    inside = ((base > lo) & (base < hi)).all(1)
    rel = t - base[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):      # one division: (hi - base) / rel or (lo - base) / rel
        room = np.where(rel != 0, np.where(rel > 0, hi - base[:, None], lo - base[:, None]) / rel, np.inf)
    f = np.clip(0.98 * room.min((1, 2)), 0.0, 1.0)[:, None, None]     # 2 % short: no tips coplanar on a plane
    inside &= f[:, 0, 0] > 0.3                                          # a stub cut to a sliver is dropped
    t = (base[:, None] + f * rel)[inside]
    m = len(t)
    return Mesh(t.reshape(-1, 3), np.arange(3 * m, dtype=np.int64).reshape(m, 3), leaves.face_class[inside],
                leaves.face_material[inside])


def hedge_body(rng: np.random.Generator, length: float, height: float = 1.2, depth: float = 0.8) -> Mesh:
    """The clipped body of a hedge along x from ``-length / 2`` to ``+length / 2`` (:func:`hedge` adds leaves).

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
    # All clumps at once, with the draws and float operations of one jittered icosphere (an ellipsoid
    # blob, turned by yaw 0) per clump in turn: each
    # clump takes 5 uniforms (3 radii, 2 centre offsets) then one jitter per sphere vertex, and
    # Generator.uniform(a, b) is a + (b - a) * random(), so one random((n, 5 + k)) block is the same stream.
    sphere = icosphere(1.0, "vegetation", "hedge_leaves", 1)
    k = len(sphere.vertices)
    u = rng.random((n, 5 + k))

    def uniform(a: float, b: float, x: np.ndarray) -> np.ndarray:
        return a + (b - a) * x

    radii = np.stack([rx * uniform(1.1, 1.3, u[:, 0]), depth / 2 * uniform(0.9, 1.0, u[:, 1]),
                      height / 2 * uniform(0.92, 1.0, u[:, 2])], 1)
    c = np.stack([xs + uniform(-0.05, 0.05, u[:, 3]) * rx, uniform(-0.04, 0.04, u[:, 4]) * depth, radii[:, 2]], 1)
    r = 1.0 + uniform(-0.12, 0.12, u[:, 5:])                       # each clump's radial noise (jitter 0.12)
    v = sphere.vertices[None] * r[:, :, None] * radii[:, None, :]
    cy, sy = np.cos(0.0), np.sin(0.0)                               # each clump's yaw 0
    v = np.stack([cy * v[..., 0] - sy * v[..., 1], sy * v[..., 0] + cy * v[..., 1], v[..., 2]], -1) + c[:, None, :]
    # clipped hedges are boxy: push the blob toward its bounding box (superellipsoid look)
    rel = (v - c[:, None, :]) / radii[:, None, :]
    v = c[:, None, :] + np.sign(rel) * np.abs(rel) ** 0.6 * radii[:, None, :]
    # squeeze the end clumps along x so the hedge spans exactly [-length/2, length/2]
    reach = np.abs(v[..., 0] - c[:, None, 0]).max(1)
    room = length / 2 - np.abs(c[:, 0])
    for i in np.nonzero(reach > room)[0]:
        v[i, :, 0] = c[i, 0] + (v[i, :, 0] - c[i, 0]) * (room[i] / reach[i])
    faces = (sphere.faces[None] + k * np.arange(n)[:, None, None]).reshape(-1, 3)
    parts = [Mesh(v.reshape(-1, 3), faces, np.tile(sphere.face_class, n), np.tile(sphere.face_material, n))]
    out = on_ground(merge(parts))
    return out
