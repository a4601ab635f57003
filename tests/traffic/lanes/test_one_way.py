"""The lane graph of a town with one-way streets (generator/traffic/lanes/one_way.py, graph.py): every
lane of a one-way segment runs its one direction, no connector leads into it against it, no dead end,
every street reaches every other without a U-turn -- over many seeds and lane counts."""

from __future__ import annotations

import pytest

from generator.layout.network.draw import make_grid
from generator.traffic.lanes.graph import LaneGraph
from kits.street_towns import one_way_spec
from kits.town_checks import check_lane_graph

GRAPH_CASES = [(seed, 1, (3, 3)) for seed in range(16)] + [(seed, 2, (4, 3)) for seed in range(4)] \
    + [(seed, 1, (2, 2)) for seed in range(4)]


@pytest.mark.parametrize("seed,lanes,blocks", GRAPH_CASES)
def test_lane_graph_runs_one_way_with_no_dead_end(seed, lanes, blocks):
    """Every lane of a one-way segment runs its direction (2 x lanes of them, none against it), no
    connector leads into a lane against it, every edge has a successor, every lane is fed by a
    connector (a one-way street's left lanes carry traffic too), and every street reaches every
    other street without a U-turn."""
    spec = one_way_spec(seed, lanes, blocks)
    grid = make_grid(spec)
    graph = LaneGraph(grid)
    ow = {s.index: grid.section(s).one_way for s in grid.segments if grid.section(s).one_way}
    if blocks == (3, 3):
        assert ow, "a 3 x 3 town with one_way weight 3 of 4 draws one-way streets"
    check_lane_graph(grid, graph)
