"""Streets crossing at an angle (issue 13): the grid -> world map of a skewed town.

The map keeps every lane, strip and sidewalk its width; rigid things keep their shape and face
along their mapped street; no two objects touch in the world; vehicles stand in the mapped lanes
and strips, and moving actors head where they go; the default towns are untouched.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from generator.geometry import apply, pose
from generator.labels import class_table
from generator.layout import build_scene
from generator.geometry.boxes import world_boxes
from generator.layout.network.draw import make_grid
from generator.layout.mapping.town_map import TownMap, draw_town_map
from generator.spec import parse_spec
from generator.traffic.build import build_world
from kits.town_checks import GROUND_KINDS, RIDERS
from kits.traffic_contacts import assert_no_contact, assert_vehicles_miss_people, static_quads



def spec_with(angle=(65.0, 65.0), seed: int = 4, traffic: dict | None = None, speed_mps: float | None = None,
              **streets):
    doc = {"name": "skewed_town", "seed": seed,
           "town": {"blocks_x": 2, "blocks_y": 2, "block_size_m": 50, "block_size_jitter_m": 6, "margin_m": 10},
           "streets": {"intersection_angle_deg": list(angle),
                       "types": {"plain": 2, "residential": 1, "boulevard": 1, "arterial": 1}, **streets},
           "density": {"bike_racks_per_block": 2, "street_objects_per_100m": 4, "riders_per_km": 20,
                       "bus_stops_per_km": 4, "walls": 0.5, "driveways": 0.5, "gravel": 0.5, "trams": 1}}
    if traffic is not None:
        doc["traffic"] = traffic
    if speed_mps is not None:
        doc["paths"] = {"speed_mps": speed_mps}
    return parse_spec(doc, "skewed_town.json")


@pytest.fixture(scope="module")
def skewed():
    spec = spec_with()
    return spec, build_scene(spec)


# -- the map itself ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("angle, lean", [(60.0, 1), (72.5, -1), (89.0, 1)])
def test_map_keeps_street_widths_and_crosses_at_the_angle(angle, lean):
    tm = TownMap(angle, lean)
    ex, ey = tm.A @ [1.0, 0.0], tm.A @ [0.0, 1.0]
    cross = np.degrees(np.arccos(ex @ ey / np.linalg.norm(ex) / np.linalg.norm(ey)))
    assert cross == pytest.approx(180.0 - angle if lean < 0 else angle, abs=1e-9)
    # a strip of width 3.5 along either grid axis is 3.5 wide across in the world
    for along, across in ((ex, tm.A @ [0.0, 3.5]), (ey, tm.A @ [3.5, 0.0])):
        u = along / np.linalg.norm(along)
        assert abs(across[0] * u[1] - across[1] * u[0]) == pytest.approx(3.5, abs=1e-9)


def test_rigid_objects_keep_their_shape_and_face_the_mapped_direction():
    tm = TownMap(63.0, -1)
    rng = np.random.default_rng(0)
    for _ in range(50):
        yaw = rng.uniform(-np.pi, np.pi)
        T = tm.rigid(pose(*rng.uniform(-100, 100, 2), 0.15, yaw, pitch=rng.uniform(-0.2, 0.2)))
        R = T[:3, :3]
        assert np.allclose(R @ R.T, np.eye(3), atol=1e-12) and np.linalg.det(R) == pytest.approx(1.0)
        d = tm.A @ [np.cos(yaw), np.sin(yaw)]
        x = R[:2, 0] / np.linalg.norm(R[:2, 0])
        assert np.allclose(x, d / np.linalg.norm(d), atol=1e-9)


def test_things_beside_a_street_keep_their_angle_to_its_kerb():
    """Along or across a street, a rigid thing keeps its angle to that street; in an intersection
    it faces the mapped direction."""
    tm = TownMap(66.0, 1, (0.0, 60.0), (0.0, 50.0), 10.0)
    street = {"ew": 0.0, "ns": float(tm.yaw(np.pi / 2))}      # world directions of the two streets
    for x, y, which in ((30.0, 4.0, "ew"), (30.0, 46.0, "ew"), (3.0, 25.0, "ns"), (57.0, 25.0, "ns")):
        grid_street = 0.0 if which == "ew" else np.pi / 2
        for yaw in (0.0, np.pi / 2, np.pi, -np.pi / 2, 0.3):
            R = tm.rigid(pose(x, y, 0.0, yaw))
            world = np.arctan2(R[1, 0], R[0, 0])
            assert np.angle(np.exp(1j * ((world - street[which]) - (yaw - grid_street)))) == pytest.approx(0.0, abs=1e-9)
    R = tm.rigid(pose(58.0, 48.0, 0.0, np.pi / 2))          # in an intersection
    assert np.arctan2(R[1, 0], R[0, 0]) == pytest.approx(street["ns"])


def test_preimage_boxes_contain_the_preimage_of_the_world_box():
    tm = TownMap(61.0, 1)
    rng = np.random.default_rng(1)
    world = np.c_[rng.uniform(-50, 50, (200, 2)), rng.uniform(0.1, 6, (200, 2)), rng.uniform(-4, 4, 200), np.zeros(200),
                  np.ones(200)]
    grid = tm.preimage_boxes(world, 0.7)
    for w, g in zip(world, grid):
        c, s = np.cos(w[4]), np.sin(w[4])
        corners = w[:2] + np.array([[a * w[2] * c - b * w[3] * s, a * w[2] * s + b * w[3] * c]
                                    for a in (-1, 1) for b in (-1, 1)])
        local = (tm.grid_xy(corners) - g[:2]) @ np.array([[np.cos(0.7), -np.sin(0.7)], [np.sin(0.7), np.cos(0.7)]])
        assert (np.abs(local) <= g[2:4] + 1e-9).all()


def test_right_angles_draw_no_map_and_the_draw_is_reproducible():
    assert draw_town_map(spec_with((90, 90))) is None
    a, b = draw_town_map(spec_with((62, 80), seed=9)), draw_town_map(spec_with((62, 80), seed=9))
    assert a == b and 62 <= a.angle_deg <= 80
    angles = {round(draw_town_map(spec_with((60, 90), seed=s)).angle_deg, 3) for s in range(8)}
    leans = {draw_town_map(spec_with((60, 89), seed=s)).lean for s in range(8)}
    assert len(angles) == 8 and leans == {-1, 1}


# -- the town in the world ---------------------------------------------------------------------------------------
def test_streets_cross_at_the_drawn_angle(skewed):
    """The route's straight stretches run along two directions only, at the drawn angle."""
    _, scene = skewed
    assert scene.town_map is not None and scene.town_map.angle_deg == pytest.approx(65.0)
    d = np.diff(scene.paths[0].points[:, :2], axis=0)
    d = d[np.linalg.norm(d, axis=1) > 0.5]
    ang = np.degrees(np.arctan2(d[:, 1], d[:, 0])) % 180.0
    ang = ang[(np.abs(np.diff(ang, prepend=ang[0])) < 1e-6)]          # straight stretches (direction constant)
    dirs = np.unique(np.round(ang, 3))
    assert len(dirs) == 2
    assert min(abs(dirs[1] - dirs[0]), 180 - abs(dirs[1] - dirs[0])) == pytest.approx(65.0, abs=1e-3)


def test_ground_is_the_grid_ground_mapped(skewed):
    """Every ground vertex lies where the map sends the grid's: the world ground is the layout's."""
    spec, scene = skewed
    tm = scene.town_map
    for o in scene.objects:
        if o.kind not in GROUND_KINDS:
            continue
        g = scene.layout.objects[o.index]
        want = tm.xy(apply(g.transform, scene.layout.prototypes[g.prototype].vertices))
        got = apply(o.transform, scene.prototypes[o.prototype].vertices)
        keep = np.ones(len(got), bool)
        if o.kind == "street":      # bay lines are turned square to the kerb (test_bay_lines_...)
            m = scene.prototypes[o.prototype]
            keep[m.faces[m.face_class == class_table().id("road_marking")].ravel()] = False
        assert np.allclose(got[keep], want[keep], atol=1e-9), o.name


def test_bay_lines_stand_square_to_the_kerb(skewed):
    """Parking bay lines (markings wholly in a side strip) are rectangles square to their street in
    the world."""
    spec, scene = skewed
    tm, lane_half = scene.town_map, make_grid(spec).lane_half
    mark = class_table().id("road_marking")
    checked = 0
    for o in scene.objects:
        if o.kind != "street":
            continue
        g = scene.layout.objects[o.index]
        street = tm.A @ g.transform[:2, 0]
        street /= np.linalg.norm(street)
        local = scene.layout.prototypes[g.prototype].vertices
        m = scene.prototypes[o.prototype]
        world = apply(o.transform, m.vertices)
        faces = m.faces[m.face_class == mark]
        for first in np.unique(faces.min(1)):
            idx = np.unique(faces[faces.min(1) == first])
            if len(idx) != 4 or (np.abs(local[idx, 1]) <= lane_half).any():
                continue
            q = world[idx, :2]
            pairs = sorted((q[j] - q[i] for i in range(4) for j in range(i + 1, 4)), key=np.linalg.norm)
            short, across = pairs[0], pairs[2]             # two short sides, two long sides, two diagonals
            assert abs(across @ street) < 1e-6 * np.linalg.norm(across), o.name
            assert abs(short[0] * street[1] - short[1] * street[0]) < 1e-6 * np.linalg.norm(short), o.name
            checked += 1
    assert checked > 20


def _footprints(scene):
    """Convex world footprints (below 1 m) of the placed objects: (name, (k, 2) hull, riding name)."""
    out = []
    for o in scene.objects:
        if o.kind in GROUND_KINDS or o.kind == "tram_rails":
            continue
        m = scene.prototypes[o.prototype]
        tri = apply(o.transform, m.vertices)[m.faces]
        low = tri[tri[:, :, 2].min(1) < 1.0].reshape(-1, 3)[:, :2]
        if len(low) < 3:
            continue
        hull = low[ConvexHull(low).vertices]
        out.append((o.name, hull, scene.objects[o.index - 1].name if o.cls in RIDERS else ""))
    return out


def _separated(p: np.ndarray, q: np.ndarray, tol: float = 1e-6) -> bool:
    for poly in (p, q):
        e = np.roll(poly, -1, 0) - poly
        for n in np.c_[-e[:, 1], e[:, 0]]:
            a, b = p @ n, q @ n
            if a.max() <= b.min() + tol * np.linalg.norm(n) or b.max() <= a.min() + tol * np.linalg.norm(n):
                return True
    return False


def test_no_two_objects_touch_in_the_world(skewed):
    _, scene = skewed
    fp = _footprints(scene)
    centre = np.array([h.mean(0) for _, h, _ in fp])
    radius = np.array([np.linalg.norm(h - h.mean(0), axis=1).max() for _, h, _ in fp])
    kinds = {o.kind for o in scene.objects}
    assert {"building", "fence", "hedge", "car", "bicycle", "tram", "wall", "bench"} <= kinds, kinds
    bad = []
    for i in range(len(fp)):
        near = np.nonzero(np.linalg.norm(centre[i + 1:] - centre[i], axis=1) < radius[i + 1:] + radius[i])[0] + i + 1
        for j in near:
            (ni, pi, ri), (nj, pj, rj) = fp[i], fp[j]
            if ri == nj or rj == ni:
                continue
            if not _separated(pi, pj):
                bad.append((ni, nj))
    assert not bad


def test_vehicles_stand_in_the_mapped_lanes_and_strips(skewed):
    spec, scene = skewed
    tm, grid = scene.town_map, make_grid(spec)
    rects = np.array([r for *_, r in grid.lane_rects()] + [r for *_, r in grid.parking_rects()])
    vehicles = [o for o in scene.objects if o.kind in ("car", "truck", "bus")]
    assert len(vehicles) > 10
    for o in vehicles:
        c = tm.grid_xy(o.box.corners_xy())
        inside = ((c[:, None, 0] >= rects[None, :, 0] - 0.01) & (c[:, None, 0] <= rects[None, :, 2] + 0.01)
                  & (c[:, None, 1] >= rects[None, :, 1] - 0.01) & (c[:, None, 1] <= rects[None, :, 3] + 0.01))
        assert inside.any(1).all(), o.name


def test_routes_keep_clear_in_the_world(skewed):
    _, scene = skewed
    from generator.layout.network.design_vehicle import EGO_HALF_WIDTH_M
    from generator.geometry.boxes import point_box_distance

    spec = skewed[0]
    limit = spec.paths.clearance_m + EGO_HALF_WIDTH_M
    things = [o for o in scene.objects if o.instance_id > 0]
    for path in scene.paths:
        d = min(point_box_distance(path.points[:, :2], o.box).min() for o in things)
        assert d >= limit - 1e-6, path.name
        step = np.linalg.norm(np.diff(path.points[:, :2], axis=0), axis=1)
        assert np.allclose(np.diff(path.s), step)


def test_same_spec_same_world():
    spec = spec_with((60, 80), seed=2)
    assert build_scene(spec).digest() == build_scene(spec).digest()


# -- traffic -----------------------------------------------------------------------------------------------------
TRAFFIC = {"cars_per_km": 20, "pedestrians_per_100m": 2, "cyclists_per_km": 4}


@pytest.mark.parametrize("seed, angle, roundabouts", [(3, 70.0, 0.5), (4, 60.0, 0.0)])
def test_traffic_touches_nothing_and_heads_where_it_goes(seed, angle, roundabouts):
    spec = spec_with((angle, angle), seed=seed, traffic=TRAFFIC, roundabouts=roundabouts)
    scene = build_scene(spec)
    world = build_world(spec, scene, 12.0)
    parked = static_quads(scene)
    vehicles = [a for a in world.actors if a.cls != "person"]
    people = [a for a in world.actors if a.cls == "person"]
    assert len(vehicles) > 5 and people
    for t in np.arange(0.0, 12.0, 0.2):
        assert_no_contact(world, t, parked)
        assert_vehicles_miss_people(world, t, vehicles, people)
    for a in vehicles:          # no crabbing: a moving vehicle's heading is its direction of travel
        t = np.arange(0.0, 12.0, 0.1)
        p = a.track.position(t)[:, :2]
        v = np.diff(p, axis=0)
        fast = np.linalg.norm(v, axis=1) > 0.1       # > 1 m/s
        if not fast.any():
            continue
        h = a.track.heading(t[:-1] + 0.05)
        err = np.angle(np.exp(1j * (np.arctan2(v[:, 1], v[:, 0]) - h)))[fast]
        assert np.abs(err).max() < np.radians(8), a.name
    E = world.ego.T_world_ego(np.array([0.0, 6.0, 12.0]))
    assert np.ptp(E[:, 0, 3]) + np.ptp(E[:, 1, 3]) > 5.0    # the ego drives


@pytest.mark.blender
def test_blender_builds_the_skewed_town_triangle_for_triangle(tmp_path):
    """Baked shaped objects and turned rigid ones reach Blender as the LiDAR sees them."""
    from kits.blender_scene import blender_matches_scene

    doc = {"name": "skewed_small", "seed": 5, "town": {"blocks_x": 1, "blocks_y": 1, "block_size_m": 40, "margin_m": 5},
           "streets": {"intersection_angle_deg": [62, 62]}}
    spec = parse_spec(doc, "skewed_small.json")
    scene = build_scene(spec)
    assert scene.town_map is not None
    blender_matches_scene(spec, scene, tmp_path)


def test_metadata_records_the_angle_the_town_was_built_with(skewed):
    from generator.spec.towns import angle_record as _angle_record

    spec, scene = skewed
    assert _angle_record(spec) == {"intersection_angle": {"angle_deg": scene.town_map.angle_deg,
                                                          "lean": scene.town_map.lean}}
    assert _angle_record(spec_with((90, 90))) == {}


def test_speeds_in_the_world_are_the_simulated_ones():
    """The map stretches lengths by 1/sin(angle); the tracks are slowed to match, so no vehicle
    passes the speed limit in the world and the ego keeps its speed (at 60 degrees the unslowed
    tracks ran 15 % faster)."""
    spec = spec_with((60.0, 60.0), seed=4, traffic={"cars_per_km": 20}, speed_mps=3.0)
    world = build_world(spec, build_scene(spec), 20.0)
    t = np.arange(0.0, 20.0, 0.1)
    fastest = max(np.linalg.norm(np.diff(a.track.position(t)[:, :2], axis=0), axis=1).max() / 0.1
                  for a in world.actors)
    assert fastest <= spec.traffic.speed_limit_mps * 1.02
    ego = np.linalg.norm(np.diff(world.ego.T_world_ego(t)[:, :2, 3], axis=0), axis=1) / 0.1
    assert 0.9 * spec.paths.speed_mps < ego.max() <= spec.paths.speed_mps * 1.02     # it reaches its speed, no more
