"""The crosswalks a vehicle's box passes over (generator.traffic.lanes.crosswalks), and the bus that
drove through a person because only the crosswalks of its entry and exit arms were checked."""

from __future__ import annotations

import numpy as np
from shapely.geometry import Polygon, box

from generator.layout.assemble import build_scene
from generator.layout.network.draw import make_grid
from generator.layout.network.measures import CROSSWALK_U
from generator.traffic.build import build_world
from generator.traffic.lanes.crosswalks import swept_arms
from generator.traffic.lanes.graph import LaneGraph
from kits.street_towns import MIX_TRAFFIC, full_spec
from kits.traffic_contacts import Box, assert_vehicles_miss_people, footprint

BUS_M = (11.8, 3.0)          #: the fleet's bus, mirrors included
RING = (2, 3)                #: a roundabout of full_spec(3)


def _painted_crosswalk(grid, node, arm: int) -> Polygon:
    """The painted crosswalk band of ``arm`` at ``node`` (across the road), as a polygon."""
    c, rh = grid.node_xy(node), grid.road_half
    a0, a1 = rh + CROSSWALK_U[0], rh + CROSSWALK_U[1]
    x0, y0, x1, y1 = {0: (a0, -rh, a1, rh), 1: (-rh, a0, rh, a1), 2: (-a1, -rh, -a0, rh), 3: (-rh, -a1, rh, -a0)}[arm]
    return box(c[0] + x0, c[1] + y0, c[0] + x1, c[1] + y1)


def test_a_bus_round_a_ring_passes_over_the_crosswalks_of_the_arms_it_passes_and_they_are_checked():
    """Entering from the west and leaving to the north, a bus's box on the compact ring reaches over
    the painted south and east crosswalks (measured here with shapely); both are among the crosswalks
    its grant waits for. A car straight across a plain node passes over its own two only."""
    grid = make_grid(full_spec(3))
    assert grid.is_roundabout(RING)
    graph = LaneGraph(grid)
    conn = graph.edges[graph.connector[(RING, 2, 1, 0)]]
    s = np.arange(0.0, conn.length, 0.25)
    p, h = conn.path.at(s)
    quads = [Polygon(footprint(Box((*q[:2], 0.0), (*BUS_M, 3.0), yaw))) for q, yaw in zip(p, h, strict=True)]
    for arm in (3, 0):
        assert any(q.intersects(_painted_crosswalk(grid, RING, arm)) for q in quads), arm
    assert set(swept_arms(graph, conn, BUS_M)) == {2, 1, 3, 0}
    plain = next(n for n in grid.nodes if not grid.is_roundabout(n) and {0, 2} <= set(grid.arms(n)))
    straight = graph.edges[graph.connector[(plain, 2, 0, 0)]]
    assert swept_arms(graph, straight, (4.6, 1.9)) == (2, 0)


def test_a_bus_on_a_ring_waits_for_a_person_on_a_crosswalk_it_swings_over():
    """Seed 3's full-mix town with 3 walkers per 100 m: at t = 15.4 s a bus going round the ring of
    (2, 3) from the west arm to the north one swung its front over the south crosswalk onto a
    person crossing there (the grant only looked at the west and north crosswalks). The run stops
    just after (the simulation is causal: a shorter run drives the same)."""
    spec = full_spec(3, traffic={**MIX_TRAFFIC, "pedestrians_per_100m": 3.0})
    world = build_world(spec, build_scene(spec), 15.6)
    people = [a for a in world.actors if a.kind == "person"]
    vehicles = [a for a in world.actors if a.kind != "person"]
    assert any(a.kind == "bus" for a in vehicles) and len(people) > 100
    for t in np.arange(0.0, 15.6, 0.1):
        assert_vehicles_miss_people(world, t, vehicles, people)
