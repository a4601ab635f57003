"""Shared streets (issue 13 item 2): paved kerb to kerb, no lane markings, bollards, 20 km/h.

What a user relies on: a shared street's carriageway is class road with the paving material and
no lane markings; its strips hold bollards and no parked car; nothing but vehicles (and the
people the shared street invites) stands on its lanes, nothing collides; moving vehicles keep
to the shared speed there; the new weight is validated like every ``streets`` field.
"""

from __future__ import annotations

import numpy as np
import pytest

from generator.errors import SpecError
from generator.geometry import apply
from generator.labels import class_table
from generator.layout import build_scene
from generator.layout.ground.roads import SURFACE
from generator.layout.network.cross_sections import SHARED_SPEED_MPS
from generator.layout.network.draw import make_grid
from generator.layout.network.grid import segment_frame_points
from generator.layout.network.measures import PARKING_START_U, STOP_U
from generator.layout.placement.shared_streets import BOLLARD_SPACING_M
from generator.materials import material_table
from generator.spec import parse_spec
from generator.traffic.build import build_world
from kits.town_checks import GROUND_KINDS, ON_LANES, no_collisions, rests_on_ground
from kits.traffic_contacts import actor_poses, assert_vehicles_miss_people


def shared_spec(seed: int = 6, traffic: dict | None = None, **types):
    doc = {"name": "shared_town", "seed": seed,
           "town": {"blocks_x": 2, "blocks_y": 2, "block_size_m": 45, "block_size_jitter_m": 6, "margin_m": 10},
           "density": {"people_per_100m": 4, "street_objects_per_100m": 2, "riders_per_km": 20,
                       "other_vehicles_per_100m": 1},
           "streets": {"types": types or {"plain": 1, "shared": 2}}}
    if traffic is not None:
        doc["traffic"] = traffic
        doc["density"]["moving_cars_per_100m"] = 0
    return parse_spec(doc, "shared_town.json")


@pytest.fixture(scope="module")
def town():
    spec = shared_spec()
    grid = make_grid(spec)
    return spec, grid, build_scene(spec)


def _shared_hit(grid, xy, margin: float = 0.0):
    for seg in grid.segments:
        if grid.section(seg).kind != "shared":
            continue
        u, v = segment_frame_points(seg, np.asarray(xy, float).reshape(1, 2))[0]
        if margin < u < seg.length - margin and abs(v) < grid.road_half:
            return seg, u, v
    return None


def _shared_v(grid, xy: np.ndarray, margin: float = 0.0) -> np.ndarray:
    """(n,) ``v`` that :func:`_shared_hit` gives each of the world points ``xy`` ((n, 2)), NaN where it gives None."""
    xy = np.asarray(xy, float).reshape(-1, 2)
    out = np.full(len(xy), np.nan)
    for seg in grid.segments:
        if grid.section(seg).kind != "shared":
            continue
        uv = segment_frame_points(seg, xy)
        hit = (np.isnan(out) & (margin < uv[:, 0]) & (uv[:, 0] < seg.length - margin)
               & (np.abs(uv[:, 1]) < grid.road_half))
        out[hit] = uv[hit, 1]
    return out


def test_shared_surface_is_paved_road_without_lane_markings(town):
    spec, grid, scene = town
    table, mats = class_table(), material_table()
    segs = [s for s in grid.segments if grid.section(s).kind == "shared"]
    assert segs and all(grid.section(s).strips == ("furnished", "furnished") for s in segs)
    for seg in segs:
        obj = next(o for o in scene.objects if o.name == f"street_{seg.index:04d}")
        mesh = scene.prototypes[obj.prototype]
        tri_uv = segment_frame_points(seg, apply(obj.transform, mesh.vertices)[:, :2])[mesh.faces]
        uv = tri_uv.mean(1)
        road = mesh.face_class == table.id("road")
        assert road.any() and (mesh.face_material[road] == mats.id(SURFACE)).all()
        assert not (mesh.face_class == table.id("parking")).any()
        marks = mesh.face_class == table.id("road_marking")
        # the only paint: the stop lines at both ends (no centre line, dividers, edge lines or bays)
        in_stop = (uv[:, 0] < STOP_U[1] + 1e-6) | (uv[:, 0] > seg.length - STOP_U[1] - 1e-6)
        assert marks.any() and in_stop[marks].all(), seg.index
        # the paving covers kerb to kerb
        span = tri_uv[road].reshape(-1, 2)
        assert np.isclose(span[:, 1].min(), -grid.road_half) and np.isclose(span[:, 1].max(), grid.road_half)
        assert np.isclose(span[:, 0].min(), 0.0) and np.isclose(span[:, 0].max(), seg.length)


def test_shared_paving_is_its_own_surface_not_the_sidewalks(town):
    """The shared carriageway's paving is a material no sidewalk, curb or other road surface of the
    town uses, with a colour of its own (so the camera and the LiDAR tell it from the pavement)."""
    spec, grid, scene = town
    table, mats = class_table(), material_table()
    shared = {f"street_{s.index:04d}" for s in grid.segments if grid.section(s).kind == "shared"}
    paving, elsewhere = set(), set()
    for o in scene.objects:
        if o.kind not in ("street", "sidewalk", "intersection", "corner"):
            continue
        m = scene.prototypes[o.prototype]
        for cls in ("road", "sidewalk", "curb"):
            ids = set(np.unique(m.face_material[m.face_class == table.id(cls)]).tolist())
            (paving if o.name in shared and cls == "road" else elsewhere).update(ids)
    assert paving == {mats.id(SURFACE)}
    assert not paving & elsewhere, [mats.rows[i].name for i in paving & elsewhere]
    colour = mats.colors[mats.id(SURFACE)].astype(int)
    for other in ("sidewalk_concrete", "curb_concrete", "asphalt"):
        assert np.abs(colour - mats.colors[mats.id(other)]).max() >= 40, other


def test_bollards_line_the_strips_and_nothing_parks_there(town):
    spec, grid, scene = town
    per_strip: dict = {}
    for o in scene.objects:
        hit = _shared_hit(grid, o.transform[:2, 3], PARKING_START_U - 0.5)     # where it stands
        if hit is None:
            continue
        seg, u, v = hit
        if grid.lane_half < abs(v) < grid.road_half:
            assert o.kind == "bollard" or o.cls == "person", o.name     # no rider, trailer or van in the row
            if o.kind == "bollard":
                per_strip.setdefault((seg.index, int(np.sign(v))), []).append(u)
        assert o.attrs.get("placement") != "parked", o.name
    assert per_strip
    for us in per_strip.values():
        gaps = np.diff(np.sort(us))
        assert len(us) >= 3 and gaps.max() <= 2 * BOLLARD_SPACING_M + 1e-6


def test_shared_town_keeps_the_layout_invariants(town):
    """Only vehicles on the lanes, and people where the street is shared or on crosswalks; nothing
    collides; everything rests on its ground; people do stand on a shared carriageway."""
    spec, grid, scene = town
    lanes = grid.drivable_rects()
    on_shared = 0
    for o in scene.objects:
        if o.kind in GROUND_KINDS:
            continue
        x, y = o.transform[:2, 3]
        if ((x > lanes[:, 0]) & (x < lanes[:, 2]) & (y > lanes[:, 1]) & (y < lanes[:, 3])).any():
            shared = o.attrs.get("placement") == "shared_street" and _shared_hit(grid, (x, y)) is not None
            on_shared += shared and o.cls == "person"
            assert o.cls in ON_LANES or o.attrs.get("placement") == "crosswalk" or shared, (o.name, o.cls)
    assert on_shared > 0
    no_collisions(scene)
    rests_on_ground(spec, grid, scene)


@pytest.fixture(scope="module")
def traffic_town():
    traffic = {"cars_per_km": 30, "trucks_per_km": 2, "buses_per_km": 1, "cyclists_per_km": 3,
               "motorcyclists_per_km": 3, "other_vehicles_per_km": 1, "pedestrians_per_100m": 1.0,
               "standing_pedestrians_per_100m": 2.0}
    spec = shared_spec(6, traffic)
    return spec, make_grid(spec), build_world(spec, build_scene(spec), 20.0)


def test_vehicles_keep_the_shared_speed_on_shared_streets(traffic_town):
    spec, grid, world = traffic_town
    n = 0
    vehicles = [a for a in world.actors if a.kind != "person"]
    for t in np.arange(0.0, 20.0, 0.25):
        v = _shared_v(grid, actor_poses(world, t, vehicles)[0], STOP_U[1] + 3.0)
        if t in (0.0, 10.0):      # all points at once answer as _shared_hit does point by point
            hits = [_shared_hit(grid, a.box(t).center[:2], STOP_U[1] + 3.0) for a in vehicles]
            assert np.array_equal(np.isnan(v), [h is None for h in hits])
            assert np.allclose(v[~np.isnan(v)], [h[2] for h in hits if h is not None], rtol=0, atol=1e-9)
        for k in np.flatnonzero(np.abs(v) < grid.lane_half):       # NaN (on no shared street) is not < anything
            n += 1
            assert vehicles[k].track.speed(t)[0] <= SHARED_SPEED_MPS + 0.05, (vehicles[k].name, t)
    assert n > 20
    # elsewhere they drive faster than that
    fast = max(a.track.speed(t)[0] for a in vehicles for t in np.arange(0.0, 20.0, 1.0))
    assert fast > SHARED_SPEED_MPS + 2.0


def test_people_stand_on_shared_carriageways_and_no_vehicle_touches_anyone(traffic_town):
    """With moving traffic, people stand on the shared streets' paving beside the lanes (road level,
    off the sidewalk); no vehicle box (ego included) meets a person's box, every 0.1 s."""
    spec, grid, world = traffic_town
    people = [a for a in world.actors if a.kind == "person"]
    vehicles = [a for a in world.actors if a.kind != "person"]
    on_shared = [a for a in people if a.attrs.get("placement") == "shared_street"]
    assert len(on_shared) >= 3 and vehicles
    for a in on_shared:
        c = a.box(0.0).center
        hit = _shared_hit(grid, c[:2])
        assert hit is not None and grid.lane_half < abs(hit[2]) < grid.road_half, a.name
        assert abs(a.track.pose(0.0)[0][2, 3]) < 1e-9       # on the road surface
    for t in np.arange(0.0, 20.0, 0.1):
        assert_vehicles_miss_people(world, t, vehicles, people)


def test_standers_keep_beyond_the_widest_vehicle_the_traffic_drives(traffic_town):
    """A stander's box stays beyond the half width of the widest vehicle driving (mirrors included)
    from the outer lane's centre; with cars only, they may stand nearer than a bus would allow."""
    spec, grid, world = traffic_town
    outer = grid.lane_half - grid.lane_w / 2
    half = max(a.size[1] / 2 for a in world.actors if a.kind != "person")
    for a in (a for a in world.actors if a.attrs.get("placement") == "shared_street"):
        corners = a.box(0.0).corners_xy()
        v = np.array([abs(_shared_hit(grid, c)[2]) if _shared_hit(grid, c) else np.inf for c in corners])
        assert v.min() >= outer + half, a.name
    cars = shared_spec(6, {"cars_per_km": 30, "standing_pedestrians_per_100m": 4.0})
    w = build_world(cars, build_scene(cars), 1.0)
    nearest = min(min(abs(_shared_hit(grid, c)[2]) for c in a.box(0.0).corners_xy())
                  for a in w.actors if a.attrs.get("placement") == "shared_street")
    assert nearest < outer + half


BAD = [
    ({"types": {"shared": -1}}, "streets.types.shared: must be a number in [0, 100], got -1"),
    ({"types": {"shared": [1]}}, "streets.types.shared: must be a number in [0, 100], got [1]"),
    ({"types": {"shared": 0, "one_way": 0}}, 'streets.types: needs a weight > 0, got {"shared": 0, "one_way": 0}'),
    ({"types": {"Shared": 1}}, "streets.types.Shared: unknown key"),
]


@pytest.mark.parametrize("streets,expected", BAD, ids=[b[1][:40] for b in BAD])
def test_bad_shared_weight_is_one_line(streets, expected):
    with pytest.raises(SpecError) as e:
        parse_spec({"name": "x", "seed": 1, "streets": streets}, "scenes/x.json")
    msg = str(e.value)
    assert msg.startswith("scenes/x.json: " + expected) and "\n" not in msg
