"""Drawing the street network of a spec: block sizes, closed streets, roundabouts, cross-sections.

The draws run in this order, each from its own named stream (so adding one never shifts another):
block sizes (``("layout", "grid")``), closures (:mod:`.closures`), roundabouts (:mod:`.roundabouts`),
then the cross-sections (:mod:`.cross_sections`: the one-way directions know the closures and
roundabouts).
"""

from __future__ import annotations

import logging
from dataclasses import replace

import numpy as np

from generator.layout.network.closures import draw_closures
from generator.layout.network.cross_sections import draw_sections
from generator.layout.network.grid import Grid, Segment
from generator.layout.network.measures import CURB_WIDTH_M, MIN_BLOCK_M, MIN_OUTER_DEPTH_M
from generator.layout.network.roundabouts import draw_roundabouts
from generator.rng import stream
from generator.spec.model import SceneSpec

log = logging.getLogger(__name__)


def make_grid(spec: SceneSpec) -> Grid:
    """Draw the block sizes (stream ``("layout", "grid")``) and build the :class:`Grid` (with the
    cross-sections and roundabouts drawn from ``spec.streets``).

    The town is centred on the world origin.
    """
    t = spec.town
    g = stream(spec.seed, "layout", "grid")
    half_j = t.block_size_jitter_m / 2
    bx = t.block_size_m + g.uniform(-half_j, half_j, t.blocks_x)
    by = t.block_size_m + g.uniform(-half_j, half_j, t.blocks_y)
    if min(bx.min(), by.min()) < MIN_BLOCK_M:
        log.warning("block size jitter would make blocks smaller than %.0f m; clipped", MIN_BLOCK_M)
    bx, by = np.maximum(bx, MIN_BLOCK_M), np.maximum(by, MIN_BLOCK_M)
    road_half = t.lanes_per_direction * t.lane_width_m + t.parking_strip_width_m
    corridor = 2 * (road_half + CURB_WIDTH_M + t.sidewalk_width_m)
    xs = np.concatenate([[0.0], np.cumsum(bx + corridor)])
    ys = np.concatenate([[0.0], np.cumsum(by + corridor)])
    xs, ys = xs - xs[-1] / 2, ys - ys[-1] / 2
    segs = []
    for j in range(len(ys)):
        for i in range(len(xs) - 1):
            segs.append(((i, j), (i + 1, j), 0, (xs[i] + road_half, ys[j]), xs[i + 1] - xs[i] - 2 * road_half))
    for i in range(len(xs)):
        for j in range(len(ys) - 1):
            segs.append(((i, j), (i, j + 1), 1, (xs[i], ys[j] + road_half), ys[j + 1] - ys[j] - 2 * road_half))
    segments = tuple(Segment(k, ax, a, b, (float(o[0]), float(o[1])), float(n))
                     for k, (a, b, ax, o, n) in enumerate(segs))
    grid = Grid(xs, ys, t.lanes_per_direction, t.lane_width_m, t.parking_strip_width_m, CURB_WIDTH_M,
                t.sidewalk_width_m, t.curb_height_m, t.margin_m, segments, max(MIN_OUTER_DEPTH_M, t.block_size_m / 2))
    # sections last (named streams: same bytes): one-way directions know the closures and roundabouts
    closed = draw_closures(spec, grid)
    if closed:
        grid = replace(grid, segments=tuple(s for s in grid.segments if s not in closed), closed=closed)
    rings = frozenset(n for n in draw_roundabouts(spec, grid) if len(grid.arms(n)) == 4)
    return replace(grid, roundabouts=rings, sections=draw_sections(spec, segments, closed, rings))
