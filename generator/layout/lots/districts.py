"""Districts: what kind of neighbourhood a block is, drawn per block from ``streets.districts``.

A district sets, for every lot of its block, the share of lots with a building, the building
height, depth and setback from the lot front (the front garden), how often the front is lined
with a hedge or a fence and how tall that is, how often a built lot is grass rather than paving,
and how many trees and bushes stand on the lots (a multiplier on the lot greenery). ``mixed``
is the town without districts: ``density`` and ``heights`` decide as before.

The lot band outside the outer ring road draws one district per section (the stretch facing a
block or an intersection). Draws: stream ``("layout", "districts")``, the blocks (row-major in
``(j, i)``) as one balanced draw, then the outer sections (in
:func:`generator.layout.lots.outskirts.outer_rows` order) as another (:func:`draw_districts`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from generator.rng import stream

Range = tuple[float, float]


@dataclass(frozen=True)
class District:
    """Lot parameters of a district (lengths in metres).

    Attributes
    ----------
    buildings : float
        Share of lots with a building.
    parks : float
        Share of unbuilt lots that are parks (else yards).
    hedge, fence : float
        Share of lot fronts lined with a hedge, with a fence (the rest have neither).
    setback_m, height_m, depth_m : (float, float)
        Building front to lot front, building height, building depth, drawn uniformly.
    front_height_m : (float, float)
        Height of the front hedge or fence.
    grass : float
        Share of built lots whose ground is grass (else paving).
    greenery : float
        Multiplier on the trees and bushes of :func:`generator.layout.placement.on_lots.place_lot_greenery`.
    """

    buildings: float
    parks: float
    hedge: float
    fence: float
    setback_m: Range
    height_m: Range
    depth_m: Range
    front_height_m: Range
    grass: float
    greenery: float


DISTRICTS: dict[str, District] = {
    "dense_centre": District(0.97, 0.3, 0.0, 0.1, (0.0, 0.8), (15.0, 30.0), (14.0, 22.0), (1.0, 1.5), 0.2, 0.5),
    "row_houses": District(0.95, 0.3, 0.3, 0.6, (2.5, 4.5), (7.0, 12.0), (9.0, 13.0), (0.9, 1.6), 0.85, 1.0),
    "detached": District(0.85, 0.4, 0.55, 0.4, (5.0, 9.0), (5.0, 9.0), (9.0, 13.0), (1.2, 2.0), 1.0, 2.0),
    "light_industry": District(0.8, 0.1, 0.1, 0.8, (4.0, 10.0), (5.0, 10.0), (15.0, 28.0), (1.8, 2.2), 0.2, 0.4),
    "park_edge": District(0.15, 0.9, 0.35, 0.25, (4.0, 8.0), (5.0, 9.0), (9.0, 13.0), (0.9, 1.6), 1.0, 1.5),
}
NAMES = ("mixed", *DISTRICTS)


def draw_districts(spec, n: int, groups: tuple[int, ...] | None = None) -> list[str]:
    """``n`` district names drawn from ``spec.streets.districts`` (all ``""`` without ``streets``).

    Each group of consecutive slots (default: one group of all ``n``) gets a *balanced* draw: the
    count of each district is ``floor`` or ``ceil`` of its weight share times the group size
    (systematic sampling on the weights' cumulative sum from one uniform draw), and the slots are
    then shuffled. Every slot still has the weight share as its probability, but a town can no longer
    draw, say, light industry on most blocks of a spec that asks for a fifth: with i.i.d. draws a 3x3
    town's mix swung by more than the gap the presets are tuned to (issue 13, ``bench/class_mix.py``).

    Parameters
    ----------
    spec : SceneSpec
    n : int
        Blocks plus outer sections, in the order of the module docstring.
    groups : tuple of int, optional
        Sizes of the groups drawn apart (summing to ``n``), e.g. ``(blocks, outer sections)``.
    """
    if spec.streets is None:
        return [""] * n
    groups = (n,) if groups is None else tuple(int(m) for m in groups)
    if sum(groups) != n:
        raise ValueError(f"district groups {groups} do not add up to {n} slots")
    w = np.array([float(spec.streets.districts.get(k, 0.0)) for k in NAMES])
    cdf = np.cumsum(w / w.sum())
    g = stream(spec.seed, "layout", "districts")
    out: list[str] = []
    for m in groups:
        if m <= 0:
            continue
        pos = (g.random() + np.arange(m)) / m
        picks = np.minimum(np.searchsorted(cdf, pos, side="right"), len(NAMES) - 1)
        out += [NAMES[int(k)] for k in g.permutation(picks)]
    return out
