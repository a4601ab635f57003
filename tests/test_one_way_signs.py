"""One-way streets read right to a driver and a camera (issue 13, street variety).

What a user relies on: a signal head stands for every approach that traffic of the lane graph
really takes into a node, and for no other (a one-way street that leaves a node has no approach
there); every one-way street carries a "one way" sign facing the traffic at its entry and a
"no entry" sign facing the traffic at the node it runs to, at its exit end; those signs are
class ``traffic_sign``, stand on the sidewalk and obey the placement rules.
"""

from __future__ import annotations

import numpy as np
import pytest

from generator.layout import build_scene
from generator.layout.streets import make_grid
from generator.traffic.lanes import LaneGraph
from test_one_way import one_way_spec
from test_street_mix import full_spec

#: one-way towns: 1 and 2 lanes per direction, and the 4 x 4 mix (shared, roundabouts, closures)
TOWNS = [("one_way", 0, 1), ("one_way", 1, 1), ("one_way", 5, 2), ("mix", 3, 1), ("mix", 8, 1)]


def _spec(kind: str, seed: int, lanes: int):
    return one_way_spec(seed, lanes) if kind == "one_way" else full_spec(seed)


@pytest.fixture(scope="module", params=TOWNS, ids=lambda t: f"{t[0]}{t[1]}x{t[2]}")
def town(request):
    spec = _spec(*request.param)
    grid = make_grid(spec)
    assert any(grid.section(s).one_way for s in grid.segments), "the town has no one-way street to check"
    return spec, grid, build_scene(spec)


def _entering_arms(graph: LaneGraph, node) -> set[int]:
    """Arms of ``node`` some lane of the lane graph enters the node from (its connectors' first arms)."""
    return {key[1] for key in graph.connector if key[0] == node}


def _arm_of(yaw: float) -> int:
    """The arm (0 east .. 3 south) a face at ``yaw`` looks along."""
    return int(np.round(yaw / (np.pi / 2))) % 4


def test_signal_heads_face_exactly_the_approaches_traffic_takes(town):
    spec, grid, scene = town
    graph = LaneGraph(grid)
    nodes = np.array([grid.node_xy(n) for n in grid.nodes])
    heads: dict = {}
    for o in scene.objects:
        if o.kind != "traffic_light":
            continue
        xy = o.transform[:2, 3]
        node = grid.nodes[int(np.argmin(np.linalg.norm(nodes - xy, axis=1)))]
        heads.setdefault(node, []).append(_arm_of(float(np.arctan2(o.transform[1, 0], o.transform[0, 0]))))
    leaving_only = 0
    for node in grid.nodes:
        if grid.is_roundabout(node):
            assert node not in heads
            continue
        entering = _entering_arms(graph, node)
        got = heads.get(node, [])
        assert sorted(got) == sorted(set(got)), f"two heads for one approach at {node}"
        assert set(got) == entering, f"node {node}: heads face arms {sorted(got)}, traffic enters from {sorted(entering)}"
        leaving_only += len(set(grid.arms(node)) - entering)
    assert leaving_only > 0, "no one-way street leaves a signalised node: the test would check nothing new"
