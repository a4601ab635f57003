"""Vegetation: trees of several species, bushes and hedges made of separate leaf clusters.

Foliage is a set of small low-poly blobs (jittered icospheres) with real gaps between them,
so LiDAR beams and camera rays pass through a crown as they do through a real one; the
label pass covers the whole crown with its convex-hull proxy (:mod:`assets_procedural.proxy`).
"""

from __future__ import annotations

import math

import numpy as np

from assets_procedural import foliage
from assets_procedural.tree_species import SPECIES, Skeleton, Species, conifer_skeleton, skeleton
from generator.geometry import Mesh, merge, on_ground, tube

CROWN_BASE_MIN = 2.4  # metres: pedestrians and cars fit under a street tree


TRI_BUDGET = 3000   #: most triangles one tree may have (branches first, then leaf clusters as fit)
CLUMP_GAP = 1.75    #: leaf clump centres stay this many clump radii apart: the gaps rays pass through
CORE = 0.58         #: a broadleaf cluster's shaded core / its radius: small enough that its leaves hide its facets


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


def _norm(d: np.ndarray) -> float:
    """``np.linalg.norm(d)`` of a (3,) vector: its sqrt(d . d), without the ~3 us of argument handling
    (a crown asks ~1500 times)."""
    return math.sqrt(d.dot(d))


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
                if all(_norm(p - q) >= gap for q in pts) and \
                        (not len(taken) or np.linalg.norm(taken - p, axis=1).min() >= keep_off):
                    pts.append(p)
    return np.array(pts).reshape(-1, 3)


def _crown(rng: np.random.Generator, sp: Species, conifer: bool, sk: Skeleton, r: float, base: float, height: float,
           room: int) -> list[Mesh]:
    """Leaf clusters round the branch tips in at most ``room`` triangles: cores, then leaf sprays.

    Cluster centres come from :func:`_clumps` (``CLUMP_GAP`` radii apart: the gaps rays pass
    through); each cluster is a shaded core of :data:`CORE` its radius (0.9 for conifer boughs) and
    sprays on the shell between 0.65 (0.75 for conifers) and 1.15 of it, pointing outward. A crown
    whose branch tips hold fewer clusters than planned grows them. Leaf sizes scale gently with the tree's height.
    """
    leaf = foliage.LEAVES[sp.leaf]
    per_cluster = 20 + sp.sprays * leaf.per_spray
    gap = (0.65 if conifer else 1.0) * CLUMP_GAP * r
    centres = _clumps(rng, sp, sk.tips, r, base, max(3, room // per_cluster), gap)
    grow = float(np.clip((max(3, room // per_cluster) / max(1, len(centres))) ** (1 / 3), 1.0, 1.5))
    radii = 0.88 * grow * r * rng.uniform(0.8, 1.15, (len(centres), 3)) * [1.0, 1.0, sp.clump_flat]
    if conifer:     # boughs: long along the branch, thin across, flat; a narrow spire at the top
        spire = (np.hypot(centres[:, 0], centres[:, 1]) < 0.3) & (centres[:, 2] > 0.75 * height)
        radii = np.where(spire[:, None], r * np.array([0.5, 0.5, 1.6]), radii * [1.6, 0.9, 1.0])
        yaw = np.arctan2(centres[:, 1], centres[:, 0])
        c, s = np.cos(yaw), np.sin(yaw)
    core = foliage.cores(rng, centres, (0.9 if conifer else CORE) * radii, "tree_crown", sp.core)
    n_spray = max(0, room - core.n_faces) // leaf.per_spray
    counts = np.full(len(centres), n_spray // max(1, len(centres)))
    counts[: n_spray - counts.sum()] += 1
    pts, out = foliage.shell(rng, centres, radii, counts, 0.65 if not conifer else 0.75, 1.15, sp.leaf_lift)
    if conifer:     # turn the shell points and the cores with their boughs
        per_core = len(core.vertices) // max(1, len(centres))
        pts = _yawed(pts, np.repeat(np.arange(len(centres)), counts), centres, c, s)
        core.vertices = _yawed(core.vertices, np.repeat(np.arange(len(centres)), per_core), centres, c, s)
    scale = float(np.clip(height / 10.0, 0.75, 1.15))
    keep = pts[:, 2] > base + 0.45 * scale      # no leaf hangs below the crown base
    return [core, foliage.sprays(rng, pts[keep], out[keep], leaf, "tree_crown", sp.leaves, scale)]


def _yawed(v: np.ndarray, owner: np.ndarray, centres: np.ndarray, c: np.ndarray, s: np.ndarray) -> np.ndarray:
    """(m, 3) points ``v`` turned about the centre of their cluster ``owner`` (m,) by its yaw (cos ``c``, sin ``s``)."""
    rel = v - centres[owner]
    return centres[owner] + np.c_[c[owner] * rel[:, 0] - s[owner] * rel[:, 1],
                                  s[owner] * rel[:, 0] + c[owner] * rel[:, 1], rel[:, 2]]


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
        leaf clusters (class ``tree_crown``): a dark 20-triangle core (the species' core material)
        ringed by sprays of leaf triangles (the species' leaf material, :mod:`assets_procedural.foliage`),
        with open gaps between clusters, at most :data:`TRI_BUDGET` triangles. The crown base is
        at least 2.4 m above the ground; the top is exactly ``height``.
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
    parts += _crown(rng, sp, species == "conifer", sk, r, base, height, TRI_BUDGET - sum(p.n_faces for p in parts))
    mesh = on_ground(merge(parts))
    # stretch everything above the crown base so the top of the crown is exactly ``height``
    z = mesh.vertices[:, 2]
    k = (height - base) / (z.max() - base)
    mesh.vertices[:, 2] = np.where(z > base, base + (z - base) * k, z)
    return mesh
