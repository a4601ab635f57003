"""Tree species: branching skeletons (trunk, recursive branches) and where their leaf clumps go.

A species is data (:class:`Species`): crown envelope, branching angles, clump sizes and
materials. :func:`skeleton` grows a trunk and ``levels`` generations of branches inside the
crown envelope and returns the branch segments and the branch tips; the builder in
:mod:`assets_procedural.vegetation` turns segments into tubes and tips into leaf clumps.
Conifers grow differently (a leader to the top with whorls of near-horizontal branches),
see :func:`conifer_skeleton`.

Frame: metres, z up, the trunk foot at the origin.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from generator.geometry import cross


@dataclass(frozen=True)
class Species:
    """How one species grows (ranges are drawn uniformly per tree)."""

    ratio: tuple[float, float]        #: crown width / crown height
    base_frac: float                  #: crown base as a fraction of the tree height
    n_main: tuple[int, int]           #: main branches off the trunk (half-open range)
    children: tuple[int, int]         #: sub-branches per branch (half-open range)
    levels: int                       #: branch generations below the trunk
    rise: tuple[float, float]         #: elevation of main branches, degrees above horizontal
    spread: float                     #: angle of a sub-branch off its parent, degrees
    clump: float                      #: leaf clump radius as a fraction of the crown radius
    clump_flat: float                 #: clump z radius / xy radius
    per_tip: tuple[int, int]          #: leaf clumps around each branch tip (half-open range)
    trunk: float                      #: trunk foot radius / tree height
    bark: str                         #: trunk and branch material
    leaves: str                       #: leaf clump material
    droop: float = 0.0                #: how far tips hang below their branch end (fraction of length)
    leaf: str = "ovate"               #: leaf look (:data:`assets_procedural.foliage.LEAVES`)
    sprays: int = 16                  #: leaf sprays a cluster is planned with (sets how many clusters fit)
    core: str = "leaf_shade"          #: material of the clusters' dark inner cores
    leaf_lift: float = 0.3            #: how strongly sprays crowd to the sunny top of a cluster


SPECIES: dict[str, Species] = {
    # London plane / maple: broad round crown on a stout trunk, wide-spreading limbs
    "plane": Species((1.0, 1.3), 0.30, (4, 6), (2, 4), 2, (25, 50), 38, 0.12, 0.7, (2, 4), 0.028, "bark_plane",
                     "leaves", leaf="broad", sprays=14),
    # linden / lime: dense upright oval crown
    "linden": Species((0.6, 0.8), 0.27, (5, 7), (2, 4), 2, (45, 65), 30, 0.12, 0.8, (2, 4), 0.024, "bark", "leaves",
                      leaf="heart", sprays=16),
    # birch: narrow, thin white trunk, steep limbs with hanging twigs, small light clumps
    "birch": Species((0.42, 0.58), 0.30, (4, 6), (2, 3), 2, (55, 72), 28, 0.1, 1.1, (2, 4), 0.016, "bark_birch",
                     "leaves_birch", droop=0.25, leaf="narrow", sprays=20, leaf_lift=0.0),
    # young street tree: staked sapling, thin trunk, a few limbs and a small sparse crown
    "young": Species((0.55, 0.8), 0.45, (3, 5), (2, 4), 1, (40, 60), 30, 0.15, 0.85, (2, 4), 0.014, "bark", "leaves",
                     leaf="ovate", sprays=18),
    # spruce / fir: a leader to the top and whorls of near-horizontal branches (conical)
    "conifer": Species((0.45, 0.6), 0.12, (5, 7), (0, 1), 0, (-8, 8), 0, 0.22, 0.4, (3, 5), 0.022, "bark",
                       "needles", leaf="needle", sprays=4, core="needles", leaf_lift=-0.2),
}


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def _turn(d: np.ndarray, angle: float, azimuth: float) -> np.ndarray:
    """``d`` (3,) turned by ``angle`` radians away from itself, toward the side ``azimuth``."""
    helper = np.array([0.0, 0.0, 1.0]) if abs(d[2]) < 0.95 else np.array([1.0, 0.0, 0.0])
    u = _unit(cross(d, helper))
    v = cross(d, u)
    side = np.cos(azimuth) * u + np.sin(azimuth) * v
    return _unit(np.cos(angle) * d + np.sin(angle) * side)


def _clip_to(p: np.ndarray, centre: np.ndarray, radii: np.ndarray, frac: float) -> np.ndarray:
    """``p`` pulled toward ``centre`` until it lies within ``frac`` of the ellipsoid ``radii``."""
    q = (p - centre) / radii
    r = float(np.linalg.norm(q))
    return p if r <= frac else centre + q * (frac / r) * radii


@dataclass
class Skeleton:
    """Branch segments and tips of one tree.

    Attributes
    ----------
    segments : list of (p0 (3,), p1 (3,), r0, r1)
        Branch tubes, metres; the first one is the trunk.
    tips : list of (3,) float
        Where leaf clumps gather (branch ends), metres, in the order clumps are granted
        (a tree's clump budget may run out before the last ones).
    """

    segments: list
    tips: list


def skeleton(rng: np.random.Generator, sp: Species, height: float, base: float, centre: np.ndarray,
             radii: np.ndarray, trunk_r: float) -> Skeleton:
    """A broadleaf skeleton: a trunk into the crown and ``sp.levels`` generations of branches.

    Parameters
    ----------
    height, base : float
        Tree top and crown base above the ground, metres.
    centre : (3,) float
        Crown envelope centre; ``radii`` (3,) its half-axes, metres.
    trunk_r : float
        Trunk radius at the foot, metres.
    """
    top = np.array([rng.normal(0, 0.04), rng.normal(0, 0.04), centre[2] + 0.35 * radii[2]])
    segs = [(np.zeros(3), top, trunk_r, trunk_r * 0.35)]
    tips = [top + [0.0, 0.0, 0.55 * radii[2]]]
    segs.append((top, tips[0], trunk_r * 0.35, trunk_r * 0.12))
    n_main = int(rng.integers(*sp.n_main))
    az0 = rng.uniform(0, 2 * np.pi)
    frontier = []
    for i in range(n_main):
        az = az0 + 2 * np.pi * (i + rng.uniform(-0.25, 0.25)) / n_main
        el = np.radians(rng.uniform(*sp.rise))
        d = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
        start = np.array([0.0, 0.0, base + rng.uniform(0.05, 0.6) * (top[2] - base)])
        start[:2] = top[:2] * (start[2] / top[2])
        end = _clip_to(start + d * 1.2 * radii.max(), centre, radii, rng.uniform(0.6, 0.8))
        r0 = trunk_r * rng.uniform(0.4, 0.5)
        segs.append((start, end, r0, r0 * 0.5))
        frontier.append((start, end, r0 * 0.5))
    for _level in range(sp.levels):
        nxt = []
        for p0, p1, r in frontier:
            d = _unit(p1 - p0)
            length = float(np.linalg.norm(p1 - p0))
            for _ in range(int(rng.integers(*sp.children))):
                s = p0 + (p1 - p0) * rng.uniform(0.45, 0.9)
                cd = _turn(d, np.radians(sp.spread * rng.uniform(0.7, 1.3)), rng.uniform(0, 2 * np.pi))
                e = s + cd * length * rng.uniform(0.45, 0.65)
                e[2] -= sp.droop * length * 0.5
                e = _clip_to(e, centre, radii, 0.92)
                if np.linalg.norm(e - s) < 0.2:
                    continue
                segs.append((s, e, r * 0.8, r * 0.35))
                nxt.append((s, e, r * 0.35))
        tips.extend(p1 for _, p1, _ in frontier)
        frontier = nxt
    tips.extend(p1 for _, p1, _ in frontier)
    return Skeleton(segs, tips[::-1])   # outermost generation first: they get their clumps first


def conifer_skeleton(rng: np.random.Generator, sp: Species, height: float, base: float, trunk_r: float) -> Skeleton:
    """A conifer: a tapering leader to ``height`` and whorls of drooping branches, longest at the bottom.

    The crown is a cone from ``base`` (width ``ratio`` * crown height) to the top.
    """
    crown_h = height - base
    r_base = 0.5 * crown_h * rng.uniform(*sp.ratio)
    segs = [(np.zeros(3), np.array([0.0, 0.0, height * 0.97]), trunk_r, trunk_r * 0.15)]
    tips = [np.array([0.0, 0.0, height * (1.0 - 0.06 * k)]) for k in range(3)]   # the spire
    n_whorls = int(np.clip(round(crown_h / 1.1), 3, 9))
    zs = base + 0.25 + (crown_h - 1.2) * (np.arange(n_whorls) / n_whorls) ** 0.9
    az0 = rng.uniform(0, 2 * np.pi)
    for k, z in enumerate(zs):
        reach = r_base * (height - z) / crown_h * rng.uniform(0.85, 1.0)
        n = int(rng.integers(*sp.n_main)) - (1 if k > n_whorls // 2 else 0)
        az0 += rng.uniform(0.4, 1.0)
        for i in range(n):
            az = az0 + 2 * np.pi * (i + rng.uniform(-0.15, 0.15)) / n
            el = np.radians(rng.uniform(*sp.rise))
            d = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
            s = np.array([0.0, 0.0, z])
            e = s + d * reach
            e[2] -= 0.12 * reach
            r0 = trunk_r * 0.3 * (height - z) / crown_h + 0.015
            segs.append((s, e, r0, r0 * 0.4))
            tips.extend([s + (e - s) * 0.8, s + (e - s) * 0.45])
    return Skeleton(segs, tips)
