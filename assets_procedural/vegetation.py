"""Vegetation: trees of several species, bushes and hedges made of separate leaf clusters.

Foliage is a set of small low-poly blobs (jittered icospheres) with real gaps between them,
so LiDAR beams and camera rays pass through a crown as they do through a real one; the
label pass covers the whole crown with its convex-hull proxy (:mod:`assets_procedural.proxy`).
"""

from __future__ import annotations

import numpy as np

from assets_procedural.tree_species import SPECIES, Skeleton, Species, conifer_skeleton, skeleton
from generator.geometry import Mesh, icosphere, merge, on_ground, tube

CROWN_BASE_MIN = 2.4  # metres: pedestrians and cars fit under a street tree


def _blob(rng: np.random.Generator, center: np.ndarray, radii: np.ndarray, cls: str, material: str,
          jitter: float = 0.18, detail: int = 1, yaw: float = 0.0) -> Mesh:
    """A leaf cluster: an ellipsoid icosphere (80 triangles, 20 at ``detail`` 0) with radial noise,
    its x half-axis turned to ``yaw`` radians."""
    m = icosphere(1.0, cls, material, detail)
    r = 1.0 + rng.uniform(-jitter, jitter, len(m.vertices))
    v = m.vertices * r[:, None] * radii
    c, s = np.cos(yaw), np.sin(yaw)
    m.vertices = np.c_[c * v[:, 0] - s * v[:, 1], s * v[:, 0] + c * v[:, 1], v[:, 2]] + center
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


TRI_BUDGET = 2000   #: most triangles one tree may have (branches first, then as many clumps as fit)
CLUMP_GAP = 1.75    #: leaf clump centres stay this many clump radii apart: the gaps rays pass through


def pick_species(rng: np.random.Generator, height: float) -> str:
    """A species for a park or yard tree ``height`` metres tall (saplings only below 7.5 m)."""
    names = [n for n in sorted(SPECIES) if n != "young" or height < 7.5]
    return str(names[int(rng.integers(len(names)))])


def _branches(sk: Skeleton, cls: str, material: str) -> list[Mesh]:
    """Capped tubes for the skeleton: the trunk with 8 sides, thinner limbs with 6 or 4."""
    out = []
    for k, (p0, p1, r0, r1) in enumerate(sk.segments):
        sides = 8 if k == 0 else (6 if r0 > 0.06 else 4)
        out.append(tube(p0, p1, max(r0, 0.012), cls, material, radius1=max(r1, 0.008), sections=sides))
    return out


def _clumps(rng: np.random.Generator, sp: Species, tips: list, r: float, floor: float, budget: int,
            gap: float, spreads=(0.5, 0.9), taken: np.ndarray | None = None, keep_off: float = 0.0) -> np.ndarray:
    """(n <= budget, 3) float: clump centres around the branch tips, ``gap`` metres apart and
    ``keep_off`` metres from the centres ``taken`` (k, 3), none lower than ``floor`` allows."""
    pts: list[np.ndarray] = []
    taken = np.zeros((0, 3)) if taken is None else taken
    for spread in spreads:      # later, looser rounds fill the crown up to the budget
        for tip in tips:
            for _ in range(int(rng.integers(*sp.per_tip))):
                if len(pts) >= budget:
                    return np.array(pts)
                p = np.asarray(tip, float) + rng.normal(0.0, spread * r, 3) * [1.0, 1.0, sp.clump_flat]
                p[2] = max(p[2], floor + r * sp.clump_flat * 1.4)   # jittered blob bottom stays above floor
                if all(np.linalg.norm(p - q) >= gap for q in pts) and \
                        (not len(taken) or np.linalg.norm(taken - p, axis=1).min() >= keep_off):
                    pts.append(p)
    return np.array(pts).reshape(-1, 3)


def tree(rng: np.random.Generator, height: float, species: str | None = None) -> Mesh:
    """A street or park tree ``height`` metres tall: trunk, recursive branches, leaf clumps.

    Parameters
    ----------
    rng : numpy.random.Generator
    height : float
        Top of the crown above the ground, metres (3-30).
    species : {"plane", "linden", "birch", "young", "conifer"}, optional
        Growth habit (:data:`assets_procedural.tree_species.SPECIES`): broad round, upright
        oval, narrow white-barked, sapling, conical. Drawn with :func:`pick_species` when omitted.

    Returns
    -------
    Mesh
        Trunk and branches (class ``tree_trunk``, the species' bark material) and separate
        leaf clumps (class ``tree_crown``, the species' leaf material; big 80-triangle clumps
        and, for broad-leaved species, small 20-triangle tufts) with open gaps between them, at most
        :data:`TRI_BUDGET` triangles. The crown base is at least 2.4 m above the ground; the top is
        exactly ``height``.
    """
    if not 3.0 <= height <= 30.0:
        raise ValueError(f"tree height must be in [3, 30] m, got {height}")
    if species is None:
        species = pick_species(rng, height)
    if species not in SPECIES:
        raise ValueError(f"tree species must be one of {sorted(SPECIES)}, got {species!r}")
    sp = SPECIES[species]
    base = max(CROWN_BASE_MIN, sp.base_frac * height * rng.uniform(0.9, 1.1))
    trunk_r = float(np.clip(sp.trunk * height * rng.uniform(0.85, 1.15), 0.05, 0.45))
    if species == "conifer":
        sk = conifer_skeleton(rng, sp, height, base, trunk_r)
        r = float(np.clip(sp.clump * 0.5 * (height - base) * np.mean(sp.ratio), 0.3, 1.0))
    else:
        rz = (height - base) / 2
        rxy = min(rz * rng.uniform(*sp.ratio), 0.45 * height)
        centre = np.array([0.0, 0.0, base + rz])
        sk = skeleton(rng, sp, height, base, centre, np.array([rxy, rxy, rz]), trunk_r)
        r = float(np.clip(sp.clump * (rxy + rz), 0.25, 1.1))
    parts = _branches(sk, "tree_trunk", sp.bark)
    used = sum(p.n_faces for p in parts)
    per_clump = 20 * 4 ** sp.detail
    room = TRI_BUDGET - used
    if sp.detail == 0:
        big = _clumps(rng, sp, sk.tips, r, base, max(4, room // per_clump), 0.8 * CLUMP_GAP * r)
        small = np.zeros((0, 3))
    else:   # broad leaves: big clumps, then small leaf tufts (20 triangles) round the branch ends
        big = _clumps(rng, sp, sk.tips, r, base, max(4, int(0.6 * room) // per_clump), CLUMP_GAP * r)
        room -= len(big) * per_clump
        small = _clumps(rng, sp, sk.tips, r, base, max(0, room // 20), 1.05 * r, (0.8, 1.0), big, 1.6 * r)
    for p in big:
        radii = r * rng.uniform(0.8, 1.15, 3) * np.array([1.0, 1.0, sp.clump_flat])
        yaw = 0.0
        if species == "conifer":      # boughs: long along the branch, thin across, flat
            spire = np.hypot(*p[:2]) < 0.3 and p[2] > 0.75 * height
            radii = r * np.array([0.5, 0.5, 1.6]) if spire else radii * [1.6, 0.9, 1.0]
            yaw = float(np.arctan2(p[1], p[0]))
        parts.append(_blob(rng, p, radii, "tree_crown", sp.leaves, detail=sp.detail, yaw=yaw))
    for p in small:
        radii = 0.5 * r * rng.uniform(0.8, 1.2, 3) * np.array([1.0, 1.0, sp.clump_flat])
        parts.append(_blob(rng, p, radii, "tree_crown", sp.leaves, 0.15, detail=0, yaw=float(rng.uniform(0, 6.3))))
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
    # All clumps at once, with the draws and float operations of one _blob per clump in turn: each
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
    r = 1.0 + uniform(-0.12, 0.12, u[:, 5:])                       # _blob's radial noise (jitter 0.12)
    v = sphere.vertices[None] * r[:, :, None] * radii[:, None, :]
    cy, sy = np.cos(0.0), np.sin(0.0)                               # _blob's yaw 0
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
