"""One-way streets (issue 13 item 2): every lane of a one-way segment runs its one direction.

What a user relies on: the lane graph has no connector into a one-way street against it and no
dead end (over many seeds); the routes and every simulated vehicle drive one-way streets only
forwards; the town keeps its layout invariants (only vehicles on the lanes, nothing colliding);
the markings have no centre line; the new weight is validated like every ``streets`` field; the
presets without it are unchanged.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from generator.cli import main
from generator.errors import SpecError
from generator.labels import class_table
from generator.layout import build_scene
from generator.layout.network.draw import make_grid
from generator.layout.network.grid import segment_frame_points
from generator.layout.network.measures import STOP_U
from generator.layout.network.one_way import driven_directions, strongly_connected
from generator.layout.network.routes import make_routes
from generator.spec import load_spec, parse_spec
from generator.traffic.build import build_world
from kits.street_towns import one_way_spec
from kits.town_checks import ON_LANES, forward, no_collisions, on_carriageways, rests_on_ground
from kits.traffic_contacts import actor_poses


def test_no_u_turn_trap_is_accepted():
    """A segment whose direction would leave a node with no way on but back (a U-turn) stays two-way."""
    spec = one_way_spec(0, blocks=(2, 2), one_way=1)
    grid = make_grid(spec)
    segs = grid.segments
    # make every arm of node (1, 1) arrive but one: the network breaks without U-turns
    into = {s.index: (1 if s.b == (1, 1) else -1) for s in segs if (1, 1) in (s.a, s.b)}
    keep_out = next(iter(into))
    into.pop(keep_out)
    assert strongly_connected(segs, {}) and not strongly_connected(segs, into)


@pytest.mark.parametrize("seed", range(8))
def test_routes_drive_one_way_streets_forwards_only(seed):
    spec = one_way_spec(seed, blocks=(3, 3), one_way=1)
    grid = make_grid(spec)
    driven = driven_directions(grid.segments, 3, 3)
    n = 0
    for s in grid.segments:
        d = grid.section(s).one_way
        if d:
            assert driven.get(s.index, {d}) == {d}
    for path in make_routes(grid):
        segs, uv = on_carriageways(grid, path.points[:, :2])
        for seg, (u, _), h in zip(segs, uv, path.headings, strict=False):
            if seg is None or not 1.0 < u < seg.length - 1.0:
                continue
            n += 1
            assert np.dot([np.cos(h), np.sin(h)], forward(seg, grid.section(seg).one_way)) > 0.99, path.name
    assert n > 0          # the routes do drive one-way streets (else this test checks nothing)


def test_both_way_streets_of_the_routes_are_never_one_way():
    spec = one_way_spec(3, blocks=(3, 3), one_way=1)
    grid = make_grid(spec)
    both = [i for i, d in driven_directions(grid.segments, 3, 3).items() if len(d) == 2]
    assert both and all(grid.sections[i].kind == "plain" and not grid.sections[i].one_way for i in both)


@pytest.fixture(scope="module")
def traffic_town():
    traffic = {"cars_per_km": 30, "trucks_per_km": 2, "buses_per_km": 1, "cyclists_per_km": 3,
               "motorcyclists_per_km": 2}
    spec = one_way_spec(4, blocks=(3, 3), traffic=traffic, plain=1, one_way=3)
    scene = build_scene(spec)
    return spec, make_grid(spec), scene, build_world(spec, scene, 12.0)


def test_every_vehicle_drives_one_way_streets_forwards(traffic_town):
    """Over 12 s (every 0.25 s) every actor and the ego on a one-way carriageway heads its way."""
    spec, grid, _, world = traffic_town
    n = 0
    for t in np.arange(0.0, 12.0, 0.25):
        xy, yaw = actor_poses(world, t)
        E = world.ego.T_world_ego(t)[0]
        xy, yaw = np.vstack([xy, [E[0, 3], E[1, 3]]]), np.r_[yaw, np.arctan2(E[1, 0], E[0, 0])]
        segs, uv = on_carriageways(grid, xy)
        for seg, (u, _), p, h in zip(segs, uv, xy, yaw, strict=True):
            if seg is None or not STOP_U[1] < u < seg.length - STOP_U[1]:
                continue
            n += 1
            fwd = forward(seg, grid.section(seg).one_way)
            assert np.dot([np.cos(h), np.sin(h)], fwd) > 0.9, (t, p)
    assert n > 50


def test_one_way_town_keeps_the_layout_invariants(traffic_town):
    """Only vehicles on the lanes, nothing colliding, everything on its ground; parked cars on a
    one-way street face its direction on both sides."""
    spec, grid, scene, _ = traffic_town
    placed = [o for o in scene.objects if o.kind not in ("street", "sidewalk", "intersection", "corner",
                                                          "lot_ground", "terrain", "horizon")]
    lanes = grid.drivable_rects()
    for o in placed:
        x, y = o.transform[:2, 3]
        if ((x > lanes[:, 0]) & (x < lanes[:, 2]) & (y > lanes[:, 1]) & (y < lanes[:, 3])).any():
            assert o.cls in ON_LANES or o.attrs.get("placement") == "crosswalk", (o.name, o.cls)
    no_collisions(scene)
    rests_on_ground(spec, grid, scene)
    parked = [o for o in scene.objects if o.attrs.get("placement") == "parked"]
    n = 0
    segs, _ = on_carriageways(grid, [np.asarray(o.box.center, float)[:2] for o in parked])
    for o, seg in zip(parked, segs, strict=True):
        if seg is not None:
            n += 1
            fwd = forward(seg, grid.section(seg).one_way)
            assert np.dot([np.cos(o.box.yaw), np.sin(o.box.yaw)], fwd) > 0.99, o.name
    assert n > 0


def test_one_way_markings_have_no_centre_line(traffic_town):
    """No marking on the centre line except the dividers' dashes (with gaps), a stop line across
    the whole carriageway only at the end the traffic arrives at, and an arrow pointing its way."""
    spec, grid, scene, _ = traffic_town
    mark = class_table().id("road_marking")
    seg = next(s for s in grid.segments if grid.section(s).one_way and s.length > 40)
    d = grid.section(seg).one_way
    obj = next(o for o in scene.objects if o.name == f"street_{seg.index:04d}")
    mesh = scene.prototypes[obj.prototype]
    tri = mesh.faces[mesh.face_class == mark]
    from generator.geometry import apply
    uv = segment_frame_points(seg, apply(obj.transform, mesh.vertices)[:, :2])[tri].mean(1)
    centre = np.abs(uv[:, 1]) < 0.1
    u_c = np.sort(uv[centre, 0])
    assert np.diff(u_c).max() > 4.0           # dashed, not a continuous line
    lh = grid.lane_half
    stop_end = (seg.length - STOP_U[1], seg.length - STOP_U[0]) if d > 0 else STOP_U
    stop_start = STOP_U if d > 0 else (seg.length - STOP_U[1], seg.length - STOP_U[0])
    in_band = lambda band: (uv[:, 0] > band[0]) & (uv[:, 0] < band[1])   # noqa: E731
    assert in_band(stop_end).any() and (np.abs(uv[in_band(stop_end), 1]) < lh).all()
    assert not (in_band(stop_start) & (np.abs(uv[:, 1]) < lh - 0.2)).any()


def test_zero_one_way_weight_draws_as_before(root):
    """Adding ``one_way: 0`` to a preset's weights changes no draw (new types go last)."""
    spec = load_spec(root / "scenes" / "kitti_like.json")
    doc = json.loads((root / "scenes" / "kitti_like.json").read_text())
    doc["streets"]["types"]["one_way"] = 0
    again = parse_spec(doc, "kitti_like.json")
    assert make_grid(again).sections == make_grid(spec).sections
    assert not any(s.one_way for s in make_grid(spec).sections)


BAD = [
    ({"types": {"one_way": -1}}, "streets.types.one_way: must be a number in [0, 100], got -1"),
    ({"types": {"one_way": "often"}}, 'streets.types.one_way: must be a number in [0, 100], got "often"'),
    ({"types": {"one_way": 0}}, 'streets.types: needs a weight > 0, got {"one_way": 0}'),
    ({"types": {"one_way": 1e309}}, "streets.types.one_way: must be a number in [0, 100]"),
]


@pytest.mark.parametrize("streets,expected", BAD, ids=[b[1][:40] for b in BAD])
def test_bad_one_way_weight_is_one_line(streets, expected):
    with pytest.raises(SpecError) as e:
        parse_spec({"name": "x", "seed": 1, "streets": streets}, "scenes/x.json")
    msg = str(e.value)
    assert msg.startswith("scenes/x.json: " + expected) and "\n" not in msg


def test_bad_one_way_weight_through_the_cli_exits_2_writes_nothing(tmp_path, capsys):
    spec = tmp_path / "x.json"
    out = tmp_path / "out"
    spec.write_text(json.dumps({"name": "x", "seed": 1, "streets": {"types": {"one_way": -2}}}))
    assert main(["layout", str(spec), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err == f"urbangen layout: {spec}: streets.types.one_way: must be a number in [0, 100], got -2\n"
    assert not out.exists()


def test_layout_summary_records_each_streets_draw():
    """``urbangen layout``'s summary lists every segment's drawn type and one-way direction (and
    nothing for a spec without ``streets``, whose summary reads as before)."""
    from generator.commands.layout import _streets

    spec = one_way_spec(0)
    grid = make_grid(spec)
    rows = _streets(spec, grid)["streets"]
    assert [r["kind"] for r in rows] == [grid.section(s).kind for s in grid.segments]
    assert {(r["segment"], r["one_way"]) for r in rows if r["one_way"]} == \
        {(s.index, grid.section(s).one_way) for s in grid.segments if grid.section(s).one_way}
    plain = parse_spec({"name": "x", "seed": 1}, "x.json")
    assert _streets(plain, make_grid(plain)) == {}


hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from kits.hostile_values import HOSTILE  # noqa: E402


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(key=st.sampled_from(["one_way", "shared"]), value=HOSTILE)
def test_hostile_new_weights_exit_2_with_one_line_and_write_nothing(tmp_path, capsys, key, value):
    import uuid

    spec = tmp_path / f"{uuid.uuid4().hex}.json"
    out = tmp_path / f"out_{spec.stem}"
    # non-finite floats go in as the Infinity/NaN tokens Python's json reads (a user's file may hold them)
    spec.write_text(json.dumps({"name": "x", "seed": 1, "streets": {"types": {"plain": 1, key: value}}}))
    assert main(["layout", str(spec), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    where = "invalid JSON" if isinstance(value, float) and value != value or value in (float("inf"), float("-inf")) \
        else "streets.types"       # a NaN/Infinity token is refused as the file's JSON, before any field
    assert err.count("\n") == 1 and err.startswith(f"urbangen layout: {spec}: {where}"), err
    assert not out.exists()
