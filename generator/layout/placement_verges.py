"""Greenery on the grass verges of residential streets and boulevards (towns with ``streets``).

A verge is the raised grass strip between the lane edge and the curb
(:mod:`generator.layout.cross_sections`). Boulevards get a row of trees down the middle of
each verge, evenly spaced at ``100 / (2 * verge_trees_per_100m)`` metres; residential verges
get trees at ``verge_trees_per_100m`` (jittered) and bushes at ``verge_bushes_per_100m``.

A verge is closer to the lanes than the sidewalk's kerb line, so a crown must stay clear of the
route keep-out: at each spot the largest tree variant that the keep-out accepts stands there
(a park tree first, then street-tree variants rebuilt smaller, as on the sidewalks). Streams
``("layout", "verge_trees")`` and ``("layout", "verge_bushes")``.
"""

from __future__ import annotations

import numpy as np

from generator.layout.placement_core import Placer
from generator.layout.placement_lots import N_TREE_VARIANTS, bush_variant, tree_variant
from generator.layout.placement_street import Street, street_tree_variants
from generator.rng import stream
from generator.spec.model import SceneSpec

END_CLEAR_M = 1.5     #: trees and bushes keep this far from a verge's ends (its end curbs)


def _verges(st: Street):
    """(segment, side, u0, u1, v) of every verge: its usable stretch and centre line."""
    grid = st.grid
    v = grid.lane_half + grid.parking_w / 2
    for seg in grid.segments:
        span = grid.strip_span(seg)
        if span is None:
            continue
        for s in (-1, 1):
            if grid.section(seg).strip(s) == "verge":
                yield seg, s, span[0] + END_CLEAR_M, span[1] - END_CLEAR_M, s * v


def place_verge_trees(placer: Placer, spec: SceneSpec, st: Street) -> None:
    """Tree rows on boulevard verges, scattered trees on residential verges."""
    if spec.streets is None or spec.streets.verge_trees_per_100m <= 0 or not st.grid.sections:
        return
    grid = st.grid
    g = stream(spec.seed, "layout", "verge_trees")
    route_v = (grid.lanes - 0.5) * grid.lane_w
    narrow = street_tree_variants(placer, spec, grid.lane_half + grid.parking_w / 2 - route_v
                                  - placer.keepout.limit - 0.1, tag="verge")
    wide = [tree_variant(placer, spec, i) for i in range(N_TREE_VARIANTS)]
    per_100 = spec.streets.verge_trees_per_100m
    for seg, s, u0, u1, v in _verges(st):
        if u1 <= u0:
            continue
        boulevard = grid.section(seg).kind == "boulevard"
        spacing = 100.0 / (2 * per_100 if boulevard else per_100)
        n = int((u1 - u0) // spacing) + 1
        if boulevard:
            us = u0 + (u1 - u0 - (n - 1) * spacing) / 2 + spacing * np.arange(n)
        else:
            us = np.sort(g.uniform(u0, u1, int(g.poisson((u1 - u0) / spacing))))
        for u in us:
            x, y = seg.to_world(u, v)[0]
            yaw = seg.yaw + int(g.integers(4)) * np.pi / 2
            for proto in (wide[int(g.integers(len(wide)))], *narrow[::-1]):
                if placer.try_place(proto, x, y, st.h, yaw, {"placement": "verge"}, pad=0.3):
                    break


def place_verge_bushes(placer: Placer, spec: SceneSpec, st: Street) -> None:
    """Bushes scattered along residential verges."""
    if spec.streets is None or spec.streets.verge_bushes_per_100m <= 0 or not st.grid.sections:
        return
    grid = st.grid
    g = stream(spec.seed, "layout", "verge_bushes")
    for seg, s, u0, u1, v in _verges(st):
        if u1 <= u0 or grid.section(seg).kind != "residential":
            continue
        for _ in range(int(g.poisson(spec.streets.verge_bushes_per_100m * (u1 - u0) / 100))):
            x, y = seg.to_world(g.uniform(u0, u1), v + g.uniform(-0.3, 0.3) * grid.parking_w / 2)[0]
            placer.try_place(bush_variant(placer, int(g.integers(1 << 16))), x, y, st.h,
                             float(g.uniform(0, 2 * np.pi)), {"placement": "verge"}, pad=0.1)
