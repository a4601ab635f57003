"""Roundabouts (issue 13 item 2): the island, the paths round it, right of way, traffic, the spec field.

Towns without ``streets.roundabouts`` (every shipped preset) are unchanged: the default town's
digest pin lives in test_layout.py; here the spec hash and the routes of a town with the field at 0
are checked equal to those without it.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from generator.errors import SpecError
from generator.geometry.boxes import quads_overlap
from generator.labels import class_table
from generator.layout.assemble import build_scene
from generator.layout.network.design_vehicle import DESIGN_VEHICLES_M, EGO_HALF_WIDTH_M, MIN_RADIUS_M, STANDARD_CAR_M
from generator.layout.network.draw import make_grid
from generator.layout.network.measures import APRON_H_M, ARM_DIRS
from generator.layout.network.rings import _closest, ring_geometry, ring_path
from generator.layout.network.routes import make_routes
from generator.spec.load import parse_spec
from generator.traffic.build import build_world
from kits.street_towns import roundabout_spec
from kits.town_checks import radii
from kits.traffic_contacts import (
    actor_quads,
    assert_no_contact,
    assert_vehicles_miss_people,
    static_quads,
)

TRAFFIC = {"cars_per_km": 25, "trucks_per_km": 2, "buses_per_km": 1, "cyclists_per_km": 3, "motorcyclists_per_km": 2,
           "other_vehicles_per_km": 1, "pedestrians_per_100m": 1.0, "standing_pedestrians_per_100m": 0.5}
MINUTE_S = 60.0

spec_with = roundabout_spec





# -- geometry ------------------------------------------------------------------------------------
CROSS_SECTIONS = [(1, 3.5, 2.4), (2, 3.5, 2.4), (1, 4.0, 2.0), (3, 3.5, 2.4), (1, 5.0, 2.0), (2, 3.0, 2.4)]


@pytest.mark.parametrize("lanes, lane_w, parking", CROSS_SECTIONS)
def test_every_ring_connector_clears_the_island_turns_no_tighter_than_the_routes_and_goes_anticlockwise(
        lanes, lane_w, parking):
    ring = ring_geometry(lanes, lane_w, lanes * lane_w + parking)
    assert ring is not None and ring.island_r > 1.0
    hw, hl = STANDARD_CAR_M[1] / 2, STANDARD_CAR_M[0] / 2
    for k in range(lanes):
        o = (k + 0.5) * lane_w
        for x in range(4):
            for y in range(4):
                if x == y:
                    continue
                p = ring_path(ring, np.zeros(2), x, y, k)
                xy, h = p.points[:, :2], p.headings
                # the car's centre line keeps its half width (and the ego's, plus a margin) off the island
                assert np.hypot(*xy.T).min() >= ring.island_r + EGO_HALF_WIDTH_M + 0.3 - 1e-9
                # so do the car's corners (its body is a rectangle)
                for dl, dw in ((hl, hw), (hl, -hw), (-hl, hw), (-hl, -hw)):
                    cx = xy[:, 0] + np.cos(h) * dl - np.sin(h) * dw
                    cy = xy[:, 1] + np.sin(h) * dl + np.cos(h) * dw
                    assert np.hypot(cx, cy).min() >= ring.island_r + 0.3 - 1e-9
                assert radii(h, p.s).min() >= MIN_RADIUS_M * (1 - 1e-3)    # chords of 5 m arcs
                # a 12 m bus and a 4.3 m wide excavator roll over the apron, never the raised centre
                for size in DESIGN_VEHICLES_M:
                    assert _closest(p, size) >= ring.core_r + 0.3 - 1e-9
                # headings are the direction of travel, continuous, and circulate anticlockwise
                chord = np.arctan2(*np.diff(xy, axis=0).T[::-1])
                assert np.abs(np.angle(np.exp(1j * (chord - h[:-1])))).max() < np.radians(3)
                assert (xy[:, 0] * np.sin(h) - xy[:, 1] * np.cos(h)).min() > 0
                # it starts on the arriving lane's centre and ends on the leaving lane's, along them
                a, b = -ARM_DIRS[x], ARM_DIRS[y]
                np.testing.assert_allclose(xy[0], -ring.entry_m * a + o * np.array([a[1], -a[0]]), atol=1e-9)
                np.testing.assert_allclose(xy[-1], ring.entry_m * b + o * np.array([b[1], -b[0]]), atol=1e-9)
                assert abs(np.angle(np.exp(1j * (h[0] - np.arctan2(a[1], a[0]))))) < 1e-9
                assert abs(np.angle(np.exp(1j * (h[-1] - np.arctan2(b[1], b[0]))))) < 1e-9


def test_no_roundabout_where_none_fits_is_a_spec_error():
    assert ring_geometry(1, 3.5, 3.5) is None         # no parking strips: the ring would need 4.6 m arcs
    with pytest.raises(SpecError) as e:
        make_grid(spec_with(lane_width_m=3.5, parking_strip_width_m=0))
    msg = str(e.value)
    assert msg.startswith("roundabout_town.json: streets.roundabouts: no roundabout fits") and "\n" not in msg


# -- the draw and the spec -----------------------------------------------------------------------
def test_roundabouts_are_drawn_on_interior_nodes_only_and_reproducibly():
    grid = make_grid(spec_with(blocks=4, share=0.5, seed=3))
    interior = {(i, j) for i in range(1, 4) for j in range(1, 4)}
    assert grid.roundabouts <= interior and 0 < len(grid.roundabouts) < 9
    assert make_grid(spec_with(blocks=4, share=0.5, seed=3)).roundabouts == grid.roundabouts
    assert make_grid(spec_with(blocks=4, share=1.0)).roundabouts == interior
    assert make_grid(spec_with(blocks=4, share=0.0)).roundabouts == frozenset()
    assert make_grid(spec_with(blocks=1, share=1.0)).roundabouts == frozenset()     # no interior node


def test_the_field_at_zero_changes_neither_the_hash_nor_the_routes(default_spec):
    assert make_grid(default_spec).roundabouts == frozenset()
    base = {"name": "x", "seed": 5, "streets": {"types": {"plain": 1, "boulevard": 1}}}
    zero = json.loads(json.dumps(base))
    zero["streets"]["roundabouts"] = 0
    a, b = parse_spec(base, "a.json"), parse_spec(zero, "a.json")
    assert a.spec_hash == b.spec_hash
    assert parse_spec({**zero, "streets": {**zero["streets"], "roundabouts": 0.3}}, "a.json").spec_hash != a.spec_hash
    for ra, rb in zip(make_routes(make_grid(a)), make_routes(make_grid(b)), strict=False):
        np.testing.assert_array_equal(ra.points, rb.points)


BAD = [(-0.1, "streets.roundabouts: must be a number in [0, 1], got -0.1"),
       (1.5, "streets.roundabouts: must be a number in [0, 1], got 1.5"),
       ("half", 'streets.roundabouts: must be a number in [0, 1], got "half"'),
       (None, "streets.roundabouts: must be a number in [0, 1], got null")]


@pytest.mark.parametrize("value, expected", BAD, ids=[str(b[0]) for b in BAD])
def test_bad_roundabouts_field_is_one_line(value, expected):
    with pytest.raises(SpecError) as e:
        parse_spec({"name": "x", "seed": 1, "streets": {"roundabouts": value}}, "scenes/x.json")
    assert str(e.value).startswith("scenes/x.json: " + expected) and "\n" not in str(e.value)


@pytest.mark.parametrize("streets, town", [({"roundabouts": 2}, {}),
                                           ({"roundabouts": 0.5}, {"parking_strip_width_m": 0})])
def test_bad_roundabouts_through_the_cli_exits_2_one_line_nothing_written(tmp_path, capsys, streets, town):
    from generator.cli import main

    spec = tmp_path / "bad.json"
    spec.write_text(json.dumps({"name": "x", "seed": 1, "town": town, "streets": streets}))
    out = tmp_path / "out"
    assert main(["layout", str(spec), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"urbangen layout: {spec}: streets.roundabouts: ") and "\n" not in err, err
    assert not out.exists()


# -- lanes and routes ----------------------------------------------------------------------------
def test_routes_go_round_the_islands_smoothly():
    grid = make_grid(spec_with(blocks=3))
    ring = grid.ring
    route = make_routes(grid)[0]
    xy, h, s = route.points[:, :2], route.headings, route.s
    assert radii(np.r_[h, h[0]], np.r_[s, route.length()]).min() >= 0.97 * MIN_RADIUS_M   # resampled arcs
    step = np.linalg.norm(np.diff(np.vstack([xy, xy[:1]]), axis=0), axis=1)
    assert step.max() <= 1.01 and step.min() > 0.5                       # no jumps, no stalls
    chord = np.arctan2(*np.diff(np.vstack([xy, xy[:1]]), axis=0).T[::-1])
    assert np.abs(np.angle(np.exp(1j * (chord - h)))).max() < np.radians(6)
    drive = grid.drivable_rects()
    inside = ((xy[:, None, 0] >= drive[:, 0]) & (xy[:, None, 0] <= drive[:, 2])
              & (xy[:, None, 1] >= drive[:, 1]) & (xy[:, None, 1] <= drive[:, 3])).any(1)
    assert inside.all()
    swept = {}
    for node in grid.roundabouts:
        d = xy - grid.node_xy(node)
        r = np.hypot(*d.T)
        assert r.min() >= ring.island_r + EGO_HALF_WIDTH_M + 0.25
        near = r < ring.ring_r[-1] + 0.5
        if near.any():
            ang = np.unwrap(np.arctan2(d[near, 1], d[near, 0]))
            swept[node] = float(ang.max() - ang.min())
            assert np.all(d[near, 0] * np.sin(h[near]) - d[near, 1] * np.cos(h[near]) > 0)   # anticlockwise
    # route 0 goes straight on at (1, 2) and (2, 2): round the island, about a half circle
    assert swept[(1, 2)] > np.radians(90) and swept[(2, 2)] > np.radians(90)


# -- the built town and its traffic --------------------------------------------------------------
@pytest.fixture(scope="module")
def town():
    spec = spec_with(blocks=2, traffic=TRAFFIC)
    scene = build_scene(spec)
    return spec, scene, build_world(spec, scene, MINUTE_S)


def test_the_island_is_raised_other_ground_with_grass_and_nothing_but_vehicles_on_the_lanes(town):
    spec, scene, _ = town
    grid = make_grid(spec)
    node, ring = (1, 1), grid.ring
    c = grid.node_xy(node)
    table = class_table()
    tri = scene.vertices[scene.faces]                    # (f, 3, 3)
    centre = tri.mean(1)
    r = np.hypot(*(centre[:, :2] - c).T)
    assert 0 < ring.core_r < ring.island_r
    top = scene.face_class[(r < ring.core_r - 0.05) & (np.abs(centre[:, 2] - grid.curb_h) < 0.01)]
    assert {table.names[i] for i in np.unique(top)} == {"other_ground", "terrain"}      # kerb band, grass
    on_apron = (r > ring.core_r + 0.05) & (r < ring.island_r - 0.05) & (np.abs(centre[:, 2] - APRON_H_M) < 0.01)
    apron = scene.face_class[on_apron]
    assert {table.names[i] for i in np.unique(apron)} == {"other_ground"}
    assert grid.ground_height(c[None])[0] == grid.curb_h
    assert grid.ground_height(c[None] + [(ring.core_r + ring.island_r) / 2, 0])[0] == APRON_H_M
    ground = ("street", "sidewalk", "intersection", "corner", "lot_ground", "terrain", "horizon")
    placed = [o for o in scene.objects if o.kind not in ground]
    assert not [o.name for o in placed if o.cls == "traffic_light" and np.hypot(*(o.transform[:2, 3] - c)) < 15]
    signs = np.array([o.transform[:2, 3] for o in placed if o.cls == "traffic_sign"])
    q = grid.walk_inner + min(0.5, grid.sidewalk_w / 2)     # the kerb line, where signals stand elsewhere
    for corner in ((1, 1), (-1, 1), (-1, -1), (1, -1)):   # a round sign at each approach instead
        assert np.hypot(*(signs - (c + q * np.array(corner))).T).min() < 0.05, corner
    assert [o for o in placed if o.cls == "traffic_light"]                # the plain nodes keep theirs
    lanes = grid.drivable_rects()
    on_lanes = ("car", "truck", "bus", "on_rails", "other_vehicle", "ridden_bicycle", "ridden_motorcycle",
                "bicyclist", "motorcyclist")
    bushes = 0
    for o in placed:
        x, y = o.transform[:2, 3]
        if np.hypot(x - c[0], y - c[1]) < ring.island_r:      # on the island: planting, wholly on the grass
            assert o.cls == "vegetation", o.name
            assert np.hypot(*(o.box.corners_xy() - c).T).max() < ring.core_r, o.name
            bushes += 1
        elif ((x > lanes[:, 0]) & (x < lanes[:, 2]) & (y > lanes[:, 1]) & (y < lanes[:, 3])).any():
            assert o.cls in on_lanes or o.attrs.get("placement") == "crosswalk", (o.name, o.cls)
    assert bushes >= 1
    # the planting intersects nothing else, and no other object reaches over the island
    isl = [o for o in placed if np.hypot(*(o.transform[:2, 3] - c)) < ring.island_r]
    rest = [o for o in placed if np.hypot(*(o.transform[:2, 3] - c)) >= ring.island_r]
    ov = quads_overlap(np.stack([o.box.corners_xy() for o in isl]), np.stack([o.box.corners_xy() for o in rest]))
    assert not ov.any()
    ov = quads_overlap(np.stack([o.box.corners_xy() for o in isl]), np.stack([o.box.corners_xy() for o in isl]))
    np.fill_diagonal(ov, False)
    assert not ov.any()
    square = np.array([[c + ring.island_r * np.array(d) for d in ((-1, -1), (1, -1), (1, 1), (-1, 1))]])
    assert not quads_overlap(square, np.stack([o.box.corners_xy() for o in rest])).any()


def test_no_vehicle_touches_a_pedestrian_at_an_unsignalled_roundabout(town):
    """No signals hold vehicles back at the roundabout: they give way to people on the crosswalks."""
    _, _, world = town
    people = [a for a in world.actors if a.kind == "person"]
    vehicles = [a for a in world.actors if a.kind != "person"]
    assert len(people) > 10 and len(vehicles) > 10
    for t in np.arange(0.0, MINUTE_S, 0.1):
        assert_vehicles_miss_people(world, t, vehicles, people)


def test_a_minute_of_traffic_through_a_roundabout_never_touches(town):
    spec, scene, world = town
    grid = make_grid(spec)
    c, ring = grid.node_xy((1, 1)), grid.ring
    parked = static_quads(scene)
    vehicles = [a for a in world.actors if a.kind != "person"]
    through = set()
    size = np.array([a.size[:2] for a in vehicles])
    small = (size[:, 0] <= STANDARD_CAR_M[0]) & (size[:, 1] <= 2 * EGO_HALF_WIDTH_M)
    along = np.linspace(0, 1, 41)[None, None, :, None]
    for t in np.arange(0.0, MINUTE_S, 0.1):
        assert_no_contact(world, t, parked)
        corners = actor_quads(world, t, vehicles) - c                       # (n, 4, 2), each box's corners
        # the box edges' closest point to the centre: sample the edges
        edges = corners[:, :, None] + (np.roll(corners, -1, 1) - corners)[:, :, None] * along
        r = np.hypot(edges[..., 0], edges[..., 1]).reshape(len(vehicles), -1).min(1)
        for k in np.flatnonzero(r <= ring.core_r):
            raise AssertionError(f"{vehicles[k].name} drives over the raised island at t={t:.1f}")
        for k in np.flatnonzero(small & (r <= ring.island_r)):
            raise AssertionError(f"{vehicles[k].name} ({vehicles[k].kind}) drives over the apron at t={t:.1f}")
        through |= {vehicles[k].name for k in np.flatnonzero(r < ring.ring_r[0] + 0.5)}
    assert len(through) >= 4, through                      # traffic does use the roundabout


def test_lidar_rays_see_the_apron_and_the_raised_grass_at_their_heights(town):
    """Embree (what the LiDAR casts with) hits the island where the meshes say: grass on the raised
    centre at curb height, other-ground on the apron 5 cm up, road beyond it."""
    from generator.lidar.caster import EmbreeCaster

    spec, scene, _ = town
    grid = make_grid(spec)
    c, ring = grid.node_xy((1, 1)), grid.ring
    table = class_table()
    radii = {"terrain": 0.0, "other_ground": (ring.core_r + ring.island_r) / 2, "road": ring.island_r + 0.5}
    heights = {"terrain": grid.curb_h + 0.003, "other_ground": APRON_H_M, "road": 0.0}
    caster = EmbreeCaster.from_scene(scene)
    for cls, r in radii.items():
        a = np.linspace(0.0, 2 * np.pi, 16, endpoint=False) + 0.1
        xy = c + r * np.stack([np.cos(a), np.sin(a)], 1)
        if cls == "terrain":      # the whole grass disc
            g = np.stack(np.meshgrid(*[np.linspace(-1, 1, 21)] * 2), -1).reshape(-1, 2) * (ring.core_r - 0.35)
            xy = c + g[np.hypot(*g.T) < ring.core_r - 0.35]
        o = np.c_[xy, np.full(len(xy), 0.6)]             # below the bushes' crowns, above the kerbs
        d = np.tile([0.0, 0.0, -1.0], (len(o), 1))
        dist, prim = caster.intersect(o, d, 5.0)[:2]
        hit = np.isfinite(dist)
        assert hit.all()
        z = 0.6 - dist
        if cls == "terrain":      # a bush may stand on the grass: the rays that reach the ground see grass
            ground = np.abs(z - heights[cls]) < 1e-3
            assert ground.sum() >= 10
            assert {table.names[i] for i in scene.face_class[prim[ground]]} == {"terrain"}
            assert {table.names[i] for i in scene.face_class[prim[~ground]]} <= {"vegetation"}
        else:
            np.testing.assert_allclose(z, heights[cls], atol=1e-3)
            assert {table.names[i] for i in scene.face_class[prim]} == {cls}
