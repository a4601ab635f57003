"""Lanes at a roundabout (generator/traffic/lanes/roundabouts.py, ring_clearance.py): connectors join
their lanes and yield to the ring, an entering vehicle waits while the ring is held, and a waiting
vehicle hangs back from where a bus swings out."""

from __future__ import annotations

import numpy as np
import pytest

from generator.layout.network.draw import make_grid
from generator.layout.network.measures import ARM_DIRS
from generator.traffic.lanes.graph import LaneGraph
from generator.traffic.lanes.signals import Signals
from generator.traffic.vehicles.sim import Vehicle, VehicleSim
from kits.street_towns import roundabout_spec as spec_with
from kits.traffic_contacts import Box, footprint, footprints, touching


def test_lane_graph_connectors_at_a_roundabout_join_their_lanes_and_yield_to_the_ring():
    grid = make_grid(spec_with(blocks=2))
    graph = LaneGraph(grid)
    node = (1, 1)
    assert grid.roundabouts == {node}
    n = 0
    for (nd, x, y, k), ci in graph.connector.items():
        if nd != node:
            continue
        conn, lin, lout = graph.edges[ci], graph.lane_in(node, x, k), graph.lane_out(node, y, k)
        np.testing.assert_allclose(conn.path.points[0], lin.path.points[-1], atol=1e-6)
        np.testing.assert_allclose(conn.path.points[-1], lout.path.points[0], atol=1e-6)
        assert graph.turn_radius(conn) == pytest.approx(min(grid.ring.fillet_r, grid.ring.ring_r[k]))
        assert (x, y, k) in graph.conflicts_at(node)[(x, y, k)]
        n += 1
    assert n == 12
    # every entry meets the ring traffic coming from its left: the left neighbour's straight on
    for x in range(4):
        assert ((x + 3) % 4, (x + 1) % 4, 0) in graph.ring_conflict[(x, (x + 2) % 4, 0)]


def test_an_entering_vehicle_waits_while_a_vehicle_on_the_ring_holds_a_conflicting_connector():
    grid = make_grid(spec_with(blocks=2))
    graph = LaneGraph(grid)
    node = (1, 1)
    signals = Signals(11, grid.nodes)
    t0 = next(t for t in np.arange(0.0, 40.0, 0.5) if all(signals.vehicles_may_enter(node, t + d) for d in range(12)))
    ring_car = graph.connector[(node, 0, 2, 0)]       # from the east, straight on round the island
    entering = graph.connector[(node, 1, 3, 0)]       # from the north, straight on: meets it on the ring
    rng = np.random.default_rng(0)
    a = Vehicle(0, 4.5, 1.9, 6.0, 1.5, [ring_car, graph.lane_out(node, 2, 0).index], 1.0, rng, v=4.0)
    lane_n = graph.lane_in(node, 1, 0)
    b = Vehicle(1, 4.5, 1.9, 8.0, 1.5, [lane_n.index, entering, graph.lane_out(node, 3, 0).index],
                lane_n.length - graph.stop_s_from_end - 6.0, rng)
    sim = VehicleSim(graph, signals, [a, b])
    a.grant = ring_car
    sim.holders[node] = {0: ring_car}
    released = granted = None
    for i in range(200):
        t = t0 + i * 0.05
        sim.step(t, 0.05)
        if released is None and a.grant is None:
            released = t
        if granted is None and b.grant == entering:
            granted = t
        pa, ha = sim.pose(a)
        pb, hb = sim.pose(b)
        qa = footprint(Box((*pa, 0.7), (4.5, 1.9, 1.5), ha))[None]
        qb = footprint(Box((*pb, 0.7), (4.5, 1.9, 1.5), hb))[None]
        assert not touching(qa, qb).any(), t
    assert released is not None and granted is not None and granted >= released


def test_a_vehicle_at_its_setback_keeps_clear_of_a_bus_swinging_out_over_its_give_way_line():
    """ring_clearance: a 12 m bus leaving the ring swings its front over the give-way line of its exit
    arm, so a vehicle waiting there must hang back; at that setback (and not at the line) its box is
    clear of every box the bus sweeps along the connector. A standard car needs no setback anywhere."""
    from generator.layout.network.rings import ring_path
    from generator.traffic.lanes.ring_clearance import setbacks

    graph = LaneGraph(make_grid(spec_with(blocks=2)))
    bus, wait = (12.0, 2.55), (12.0, 2.55)
    for x in range(4):
        for y in range(4):
            if x == y:
                continue
            assert setbacks(graph, (x, y, 0), (4.8, 2.1), 2.55) == {}
            sb = setbacks(graph, (x, y, 0), bus, wait[1])
            assert set(sb) == {(y, 0)} and sb[(y, 0)] > 1.0, sb
            p = ring_path(graph.grid.ring, np.zeros(2), x, y, 0)
            swept = footprints([Box((*q[:2], 1.5), (*bus, 3.0), float(h)) for q, h in zip(p.points, p.headings,
                                                                                          strict=False)])
            a = -np.asarray(ARM_DIRS[y])
            right = np.array([a[1], -a[0]])
            for back, clear in ((sb[(y, 0)], True), (0.0, False)):
                centre = -a * (graph.stop_m + back + wait[0] / 2) + right * graph.grid.lane_w / 2
                box = footprint(Box((*centre, 1.5), (*wait, 3.0), float(np.arctan2(a[1], a[0]))))
                assert touching(box[None], swept).any() != clear, (x, y, back)
