"""Districts: what kind of neighbourhood a block is, drawn per block from ``streets.districts``.

A district sets, for every lot of its block, the share of lots with a building, the building
height, depth and setback from the lot front (the front garden), how often the front is lined
with a hedge or a fence and how tall that is, how often a built lot is grass rather than paving,
and how many trees and bushes stand on the lots (a multiplier on the lot greenery). ``mixed``
is the town without districts: ``density`` and ``heights`` decide as before.

The lot band outside the outer ring road draws one district per section (the stretch facing a
block or an intersection). Draws: stream ``("layout", "districts")``, blocks row-major in
``(j, i)``, then the outer sections in :func:`generator.layout.outskirts.outer_rows` order.
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
        Multiplier on the trees and bushes of :func:`generator.layout.placement_lots.place_lot_greenery`.
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


def draw_districts(spec, n: int) -> list[str]:
    """``n`` district names drawn from ``spec.streets.districts`` (all ``""`` without ``streets``).

    Parameters
    ----------
    spec : SceneSpec
    n : int
        Blocks plus outer sections, in the order of the module docstring.
    """
    if spec.streets is None:
        return [""] * n
    w = np.array([float(spec.streets.districts.get(k, 0.0)) for k in NAMES])
    g = stream(spec.seed, "layout", "districts")
    return [NAMES[int(k)] for k in g.choice(len(NAMES), size=n, p=w / w.sum())]
