"""Trees in the pocket parks of closed streets (:mod:`generator.layout.network.closures`).

Two rows of park trees, one on the grass either side of the footpath, about every
``PARK_TREE_SPACING_M`` metres with jitter; each stands only where the occupancy and the route
keep-out accept it. Stream ``("layout", "closed_streets", "trees", segment index)``.
"""

from __future__ import annotations

import numpy as np

from generator.layout.ground.parks import PATH_HALF_M
from generator.layout.placement.on_lots import N_TREE_VARIANTS, tree_variant
from generator.layout.placement.placer import Placer
from generator.rng import stream

PARK_TREE_SPACING_M = 9.0


def plant_parks(placer: Placer, spec, grid, z: float) -> int:
    """Plant the parks of every closed segment of ``grid``; returns how many trees stood."""
    placed = 0
    v_row = PATH_HALF_M + (grid.road_half - PATH_HALF_M) / 2     # middle of the grass either side
    u0 = grid.corridor_half - grid.road_half + 2.0
    for seg in grid.closed:
        g = stream(spec.seed, "layout", "closed_streets", "trees", seg.index)
        for side in (-1, 1):
            u = u0 + g.uniform(0.0, PARK_TREE_SPACING_M / 2)
            while u < seg.length - u0:
                x, y = seg.to_world(u, side * v_row)[0]
                proto = tree_variant(placer, spec, int(g.integers(N_TREE_VARIANTS)))
                placed += bool(placer.try_place(proto, x, y, z, float(g.uniform(0, 2 * np.pi)), pad=0.3))
                u += PARK_TREE_SPACING_M * g.uniform(0.8, 1.2)
    return placed
