"""Closed streets (issue 13 item 2, T-junctions and merged blocks): a share of the interior segments
no route drives become pocket parks; lanes, routes, crosswalks and walkers avoid them.

Towns without ``streets.closed_streets`` are unchanged (the digest pin in test_layout.py; the spec
hash with the field at 0 below).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from generator.errors import SpecError
from generator.labels import class_table
from generator.layout.assemble import build_scene
from generator.layout.network.cycles import route_pairs
from generator.layout.network.draw import make_grid
from generator.layout.network.measures import CROSSWALK_U
from generator.layout.network.routes import make_routes
from generator.spec.load import parse_spec
from generator.traffic.build import build_world
from generator.traffic.lanes.graph import LaneGraph
from kits.traffic_contacts import actor_poses, assert_no_contact, static_quads

TRAFFIC = {"cars_per_km": 25, "trucks_per_km": 2, "buses_per_km": 1, "cyclists_per_km": 3, "motorcyclists_per_km": 2,
           "other_vehicles_per_km": 1, "pedestrians_per_100m": 1.5, "standing_pedestrians_per_100m": 0.5}


def spec_with(blocks: int = 2, share: float = 1.0, seed: int = 11, traffic: dict | None = None, **streets):
    doc = {"name": "closed_town", "seed": seed,
           "town": {"blocks_x": blocks, "blocks_y": blocks, "block_size_m": 45, "block_size_jitter_m": 6,
                    "margin_m": 10},
           "density": {"moving_cars_per_100m": 0}, "streets": {"closed_streets": share, **streets}}
    if traffic is not None:
        doc["traffic"] = traffic
    return parse_spec(doc, "closed_town.json")


def _in_corridor(grid, seg, xy: np.ndarray, half: float) -> np.ndarray:
    x0, y0, x1, y1 = seg.rect_world(0.0, seg.length, -half, half)
    return (xy[:, 0] > x0) & (xy[:, 0] < x1) & (xy[:, 1] > y0) & (xy[:, 1] < y1)


def _connected(grid) -> bool:
    adj = {n: [] for n in grid.nodes}
    for s in grid.segments:
        adj[s.a].append(s.b)
        adj[s.b].append(s.a)
    seen, todo = {grid.nodes[0]}, [grid.nodes[0]]
    while todo:
        for m in adj[todo.pop()]:
            if m not in seen:
                seen.add(m)
                todo.append(m)
    return len(seen) == len(grid.nodes)


@pytest.mark.parametrize("blocks, seed", [(2, 11), (3, 1), (4, 7), (5, 3)])
def test_closures_spare_the_routes_and_the_outer_ring_and_keep_the_network_whole(blocks, seed):
    grid = make_grid(spec_with(blocks=blocks, seed=seed))
    assert grid.closed
    n = blocks
    on_route = route_pairs(n, n)
    for seg in grid.closed:
        assert frozenset((seg.a, seg.b)) not in on_route
        assert not ((seg.axis == 0 and seg.a[1] in (0, n)) or (seg.axis == 1 and seg.a[0] in (0, n)))
        assert seg not in grid.segments
    assert all(len(grid.arms(node)) >= 2 for node in grid.nodes)
    assert _connected(grid)
    assert make_grid(spec_with(blocks=blocks, seed=seed)).closed == grid.closed        # reproducible
    assert make_grid(spec_with(blocks=blocks, share=0.0, seed=seed)).closed == ()


def test_lanes_routes_and_roundabouts_avoid_the_closed_segments():
    grid = make_grid(spec_with(blocks=4, share=0.3, seed=7, roundabouts=1.0))
    assert grid.closed
    graph = LaneGraph(grid)
    pts = np.concatenate([e.path.points[:, :2] for e in graph.edges]
                         + [r.points[:, :2] for r in make_routes(grid)])
    for seg in grid.closed:
        assert not _in_corridor(grid, seg, pts, grid.road_half).any()
        for node in (seg.a, seg.b):
            assert node not in grid.roundabouts               # a roundabout needs four arms
        mid = seg.to_world(seg.length / 2, 0.0)
        assert grid.ground_height(mid)[0] == grid.curb_h       # the park is at kerb height
    assert grid.roundabouts                                    # the four-arm interior nodes still have them
    # every lane leads on: a vehicle never reaches a dead end
    for e in graph.edges:
        assert e.succ, e.path.name


def test_zero_leaves_the_spec_hash_and_bad_values_are_one_line():
    base = {"name": "x", "seed": 5, "streets": {"types": {"plain": 1}}}
    zero = {"name": "x", "seed": 5, "streets": {"types": {"plain": 1}, "closed_streets": 0}}
    assert parse_spec(base, "a.json").spec_hash == parse_spec(zero, "a.json").spec_hash
    for value in (-0.5, 2, "all", None):
        with pytest.raises(SpecError) as e:
            parse_spec({"name": "x", "seed": 1, "streets": {"closed_streets": value}}, "scenes/x.json")
        msg = str(e.value)
        assert msg.startswith("scenes/x.json: streets.closed_streets: must be a number in [0, 1], got ")
        assert "\n" not in msg


def test_bad_closed_streets_through_the_cli_exits_2_writes_nothing(tmp_path, capsys):
    from generator.cli import main

    spec = tmp_path / "bad.json"
    spec.write_text(json.dumps({"name": "x", "seed": 1, "streets": {"closed_streets": 1.5}}))
    out = tmp_path / "out"
    assert main(["layout", str(spec), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"urbangen layout: {spec}: streets.closed_streets: ") and "\n" not in err
    assert not out.exists()


@pytest.fixture(scope="module")
def town():
    # seed 11 drove a slewed excavator into a parked car (fixed: moving excavators travel straight,
    # generator/traffic/fleet.py); its walker below kerb height in a closed street's corridor is
    # test_feet_on_the_ground_under_them below
    spec = spec_with(blocks=2, seed=5, traffic=TRAFFIC)
    scene = build_scene(spec)
    return spec, scene, build_world(spec, scene, 60.0)


def test_the_park_is_grass_and_a_path_with_trees_and_nothing_else(town):
    spec, scene, _ = town
    grid = make_grid(spec)
    assert len(grid.closed) == 2
    table = class_table()
    tri = scene.vertices[scene.faces]
    centre = tri.mean(1)
    ground = ("street", "sidewalk", "intersection", "corner", "lot_ground", "terrain", "horizon")
    placed = [o for o in scene.objects if o.kind not in ground]
    is_ground = np.array([o.kind in ground for o in scene.objects])[scene.face_object]
    for seg in grid.closed:
        inner = _in_corridor(grid, seg, centre[:, :2], grid.road_half - 0.05) & is_ground
        u = (centre[:, :2] - np.asarray(seg.origin)) @ np.array([np.cos(seg.yaw), np.sin(seg.yaw)])
        inner &= (u > grid.corridor_half - grid.road_half + 0.05) & (u < seg.length - grid.corridor_half
                                                                     + grid.road_half - 0.05)
        flat = inner & (np.abs(tri[:, :, 2] - grid.curb_h).max(1) < 1e-3)     # the ground at kerb height
        assert {table.names[i] for i in np.unique(scene.face_class[flat])} == {"terrain", "sidewalk"}
        below = inner & (tri[:, :, 2].min(1) < grid.curb_h - 1e-3)
        assert not below.any()                                # no ground lower: no road left
        anchors = np.array([o.transform[:2, 3] for o in placed])
        on = _in_corridor(grid, seg, anchors, grid.road_half)
        assert on.any() and {placed[i].kind for i in np.flatnonzero(on)} == {"tree"}


def test_a_minute_of_traffic_and_walkers_round_the_closed_streets(town):
    spec, scene, world = town
    grid = make_grid(spec)
    parked = static_quads(scene)
    people = [a for a in world.actors if a.kind == "person"]
    vehicles = [a for a in world.actors if a.kind != "person"]
    assert len(people) > 10 and len(vehicles) > 10
    for t in np.arange(0.0, 60.0, 0.1):
        assert_no_contact(world, t, parked)
        vc = actor_poses(world, t, vehicles)[0]
        for seg in grid.closed:
            assert not _in_corridor(grid, seg, vc, grid.road_half).any(), f"a vehicle in a park at t={t:.1f}"
    for a in people:        # people on a closed street walk its sidewalks and caps, at kerb height
        xyz = a.track.xyz
        for seg in grid.closed:
            inside = _in_corridor(grid, seg, xyz[:, :2], grid.corridor_half)
            assert np.all(xyz[inside, 2] > grid.curb_h - 0.02), a.name
            cap = grid.corridor_half - grid.road_half          # the kerbed caps at the ends are sidewalk
            x0, y0, x1, y1 = seg.rect_world(cap, seg.length - cap, -(grid.road_half - 0.3), grid.road_half - 0.3)
            park = (xyz[:, 0] > x0) & (xyz[:, 0] < x1) & (xyz[:, 1] > y0) & (xyz[:, 1] < y1)
            assert not park.any(), f"{a.name} walks in a park"


WALKERS = {"pedestrians_per_100m": 3.0, "standing_pedestrians_per_100m": 0.5}


def _on_crossing(grid, xy: np.ndarray) -> np.ndarray:
    """(n,) bool: on the road inside the crosswalk band of an open street's end."""
    out = np.zeros(len(xy), bool)
    for seg in grid.segments:
        d = xy - np.asarray(seg.origin)
        u, v = (d[:, 0], d[:, 1]) if seg.axis == 0 else (d[:, 1], -d[:, 0])
        for from_edge in (u, seg.length - u):
            out |= (from_edge >= CROSSWALK_U[0]) & (from_edge <= CROSSWALK_U[1]) & (np.abs(v) < grid.road_half)
    return out


# seed 11 once failed; seed 5 a second town of the same kind (3 and 8 drove the same code a third and fourth time)
@pytest.mark.parametrize("seed", [5, 11])
def test_feet_on_the_ground_under_them(seed):
    """Every sample of every person (the lead-in before t = 0 included) stands on the ground under
    its centre: kerb height on the pavement and in the closed streets' corridors (caps, corners,
    the sidewalks along the park), 0 on the road, and walkers are on the road only on crossings.
    (Seed 11 once put a walker half-way down a kerb ramp inside a closed street's corner.)"""
    spec = spec_with(blocks=2, seed=seed, traffic=WALKERS)
    grid = make_grid(spec)
    assert grid.closed
    world = build_world(spec, build_scene(spec), 30.0)
    people = [a for a in world.actors if a.kind == "person"]
    walkers = [a for a in people if a.attrs["role"] == "walking"]
    assert len(walkers) > 10
    for a in people:
        xyz = a.track.xyz
        ground = grid.ground_height(xyz[:, :2])
        bad = np.flatnonzero(np.abs(xyz[:, 2] - ground) > 1e-6)
        assert not len(bad), (f"{a.name} sample {bad[0]}: feet at {xyz[bad[0], 2]:.4f} m "
                              f"on ground at {ground[bad[0]]:.4f} m")
        for seg in grid.closed:
            inside = _in_corridor(grid, seg, xyz[:, :2], grid.corridor_half)
            assert np.all(np.abs(xyz[inside, 2] - grid.curb_h) < 1e-6), a.name
    xy = np.concatenate([a.track.xyz[:, :2] for a in walkers])
    z = np.concatenate([a.track.xyz[:, 2] for a in walkers])
    road = z < 1e-6
    assert road.any() and (np.abs(z - grid.curb_h) < 1e-6).any()    # some cross, most walk the pavement
    assert _on_crossing(grid, xy[road]).all()
