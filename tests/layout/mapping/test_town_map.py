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
from generator.layout.mapping.town_map import TownMap, draw_town_map
from generator.layout.network.draw import make_grid
from kits.street_towns import skewed_spec as spec_with
from kits.town_checks import GROUND_KINDS, RIDERS


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
            assert np.angle(np.exp(1j * ((world - street[which]) - (yaw - grid_street)))) == pytest.approx(0.0,
                                                                                                           abs=1e-9)
    R = tm.rigid(pose(58.0, 48.0, 0.0, np.pi / 2))          # in an intersection
    assert np.arctan2(R[1, 0], R[0, 0]) == pytest.approx(street["ns"])


def test_preimage_boxes_contain_the_preimage_of_the_world_box():
    tm = TownMap(61.0, 1)
    rng = np.random.default_rng(1)
    world = np.c_[rng.uniform(-50, 50, (200, 2)), rng.uniform(0.1, 6, (200, 2)), rng.uniform(-4, 4, 200), np.zeros(200),
                  np.ones(200)]
    grid = tm.preimage_boxes(world, 0.7)
    for w, g in zip(world, grid, strict=False):
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
    from generator.geometry.boxes import point_box_distance
    from generator.layout.network.design_vehicle import EGO_HALF_WIDTH_M

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


def _route_directions(scene) -> np.ndarray:
    """Directions (degrees in [0, 180)) of the straight stretches of route 0 in the world."""
    d = np.diff(scene.paths[0].points[:, :2], axis=0)
    d = d[np.linalg.norm(d, axis=1) > 0.5]
    ang = np.degrees(np.arctan2(d[:, 1], d[:, 0])) % 180.0
    ang = ang[(np.abs(np.diff(ang, prepend=ang[0])) < 1e-6)]          # straight stretches (direction constant)
    return np.unique(np.round(ang, 3))


def test_metadata_records_the_angle_the_town_was_built_with(skewed, tmp_path):
    """The angle and lean a LiDAR sequence's ``lidar_meta.json`` and an image's JSON record are the
    ones the streets of the scanned town cross at: x-streets run along 0 degrees, y-streets along the
    angle (lean +1, towards +x going north) or 180 degrees less it (lean -1)."""
    import json

    from generator.jobs.lidar_sequence import SequenceOptions, write_sequence
    from generator.jobs.variants import render_frame
    from generator.lidar.sensors import load_preset
    from generator.spec.render import load_render_config
    from generator.spec.towns import angle_record
    from generator.world.rig import Rig
    from kits.fake_renderer import FakeRenderer

    spec, scene = skewed
    write_sequence(scene, spec, tmp_path / "lidar", SequenceOptions(frames=1, sequence="00", threads=1),
                   sensor=load_preset("vlp16"), progress=False)
    lidar = json.loads((tmp_path / "lidar" / "sequences" / "00" / "lidar_meta.json").read_text())
    frame = Rig.from_spec(spec, scene).frame(0)
    render_frame(FakeRenderer(24, 32), spec, load_render_config("test"), frame, tmp_path / "cam", [("day", "clear")])
    image = json.loads(next((tmp_path / "cam").rglob("*.json")).read_text())
    dirs = _route_directions(scene)
    assert dirs[0] == pytest.approx(0.0, abs=1e-3) and len(dirs) == 2
    for written in (lidar["scene"]["intersection_angle"], image["intersection_angle"]):
        angle, lean = written["angle_deg"], written["lean"]
        assert 0.0 < angle < 90.0 and lean in (-1, 1)
        assert dirs[1] == pytest.approx(angle if lean > 0 else 180.0 - angle, abs=1e-3)
    assert angle_record(spec_with((90, 90))) == {}     # right-angle towns write no record
