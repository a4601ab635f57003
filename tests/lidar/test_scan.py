"""Casting against small scenes with known answers: ground rings, a box, threads, motion skew."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from generator.geometry import box, convex_hull, rect
from generator.labels import class_table
from generator.lidar.caster import EmbreeCaster
from generator.lidar.scan import POINT_DTYPE, Scanner
from generator.lidar.sensors import load_preset
from generator.materials import material_table
from generator.world import rig
from generator.world.rig import Rig
from kits.scene_kit import scene_of, straight_path

H = 1.73  # KITTI mount height


@pytest.fixture(scope="module")
def hdl64e():
    return load_preset("hdl64e")


@pytest.fixture(scope="module")
def ground_scene():
    return scene_of([("ground", rect(-400, -400, 400, 400, 0.0, "road", "asphalt"), 0)])


def test_ground_rings_land_at_the_analytic_range(hdl64e, ground_scene):
    s = hdl64e
    with Scanner(ground_scene, s, threads=2) as sc:
        scan = sc.scan(rig.mount((0, 0, H), (0, 0, 0)))
    p = scan.points
    order = s.by_ring
    v, vo, ho = s.elevation[order], s.vert_offset[order], s.horiz_offset[order]
    z_emit = H + vo * np.cos(v)  # the driver's vertical offset raises the emission point
    expected_range = np.where(v < 0, z_emit / np.sin(-np.minimum(v, -1e-12)), np.inf)
    hits_expected = expected_range <= s.max_range_m
    counts = np.bincount(p["ring"], minlength=s.n_lasers)
    # every column of every ring whose analytic range is within 120 m returns; the others never do
    assert np.array_equal(counts[hits_expected], np.full(hits_expected.sum(), s.azimuth_steps))
    assert counts[~hits_expected].sum() == 0
    assert hits_expected.sum() >= 50
    ring = p["ring"]
    np.testing.assert_allclose(p["range"], expected_range[ring], atol=1e-3, rtol=0)
    # horizontal distance from the emission point is h/tan(-v); from the sensor axis add the offsets
    horiz_from_emitter = z_emit[ring] / np.tan(-v[ring])
    radial = np.hypot(horiz_from_emitter - vo[ring] * np.sin(v[ring]), ho[ring])
    np.testing.assert_allclose(np.hypot(p["x"], p["y"]), radial, atol=1e-3, rtol=0)
    np.testing.assert_allclose(p["z"], -H, atol=1e-3)
    np.testing.assert_allclose(p["cos_incidence"], np.sin(-v[ring]), atol=1e-5)
    assert np.all(p["class"] == class_table().id("road")) and np.all(p["instance"] == 0)
    assert np.all(p["material"] == material_table().id("asphalt"))


def test_box_returns_its_distance_class_and_instance(hdl64e):
    s = hdl64e
    car = class_table().id("car")
    scene = scene_of([("ground", rect(-200, -200, 200, 200, 0.0, "road", "asphalt"), 0),
                      ("car_0001", box((2.0, 4.0, 4.0), "car", "car_paint", center=(13.0, 0.0, 2.0)), 7)])
    with Scanner(scene, s, threads=2) as sc:
        scan = sc.scan(rig.mount((0, 0, H), (0, 0, 0)))
    p = scan.points[scan.points["class"] == car]
    assert len(p) > 500
    assert np.all(p["instance"] == 7) and np.all(p["material"] == material_table().id("car_paint"))
    # the front face is at x = 12 m; the box is taller than the sensor, so only that face is seen
    np.testing.assert_allclose(p["x"], 12.0, atol=1e-3)
    origins, dirs, _ = s.local_rays()
    o, d = origins[p["column"], p["ring"]], dirs[p["column"], p["ring"]]
    np.testing.assert_allclose(p["range"], (12.0 - o[:, 0]) / d[:, 0], atol=1e-3, rtol=0)
    np.testing.assert_allclose(p["cos_incidence"], d[:, 0], atol=1e-5)
    # nothing from the ground shows through the box: no road point lies beyond it inside its shadow
    road = scan.points[scan.points["class"] == class_table().id("road")]
    behind = (road["x"] > 12.5) & (np.abs(road["y"]) < 1.5 * road["x"] / 12.0 - 0.3)
    assert not behind.any()


def test_points_only_within_the_sensor_range(hdl64e):
    near = scene_of([("ground", rect(-200, -200, 200, 200, 0.0, "road", "asphalt"), 0),
                     ("pole", box((0.2, 0.2, 4.0), "pole", "pole_metal", center=(0.6, 0.0, 2.0)), 3)])
    with Scanner(near, hdl64e, threads=1) as sc:
        p = sc.scan(rig.mount((0, 0, H), (0, 0, 0))).points
    assert p["range"].min() >= hdl64e.min_range_m and p["range"].max() <= hdl64e.max_range_m
    # the pole 0.5 m away is inside the minimum range: blocked, no return, no pole label
    assert not np.any(p["class"] == class_table().id("pole"))


def test_casts_real_geometry_not_label_proxies(hdl64e):
    crown = box((1.0, 1.0, 1.0), "tree_crown", "leaves", center=(8.0, 0.0, 2.0))
    scene = scene_of([("crown", crown, 5)])
    scene.proxies["crown_hull"] = convex_hull(box((6.0, 6.0, 6.0), "tree_crown", "leaves", center=(8.0, 0.0, 2.0)),
                                              "tree_crown")
    scene.objects[0].proxy = "crown_hull"
    with Scanner(scene, hdl64e, threads=1) as sc:
        p = sc.scan(rig.mount((0, 0, H), (0, 0, 0))).points
    # the small real crown (front at 7.5 m), not the 6 m hull (front at 5 m)
    assert len(p) and p["x"].min() > 7.5 - 1e-3


def test_threads_give_identical_points(hdl64e):
    scene = scene_of([("ground", rect(-200, -200, 200, 200, 0.0, "road", "asphalt"), 0),
                      ("car", box((4.0, 2.0, 1.5), "car", "car_paint", center=(6.0, 4.0, 0.75)), 1),
                      ("wall", box((1.0, 30.0, 8.0), "building", "facade_brick", center=(-15.0, 0.0, 4.0)), 2)])
    caster = EmbreeCaster.from_scene(scene)
    pose = rig.mount((0, 0, H), (0, 0, 0))
    with Scanner(scene, hdl64e, threads=1, caster=caster) as one, Scanner(scene, hdl64e, threads=2,
                                                                          caster=caster) as two:
        a, b = one.scan(pose).points, two.scan(pose).points
    assert a.dtype == POINT_DTYPE and a.tobytes() == b.tobytes()


def test_float32_recentring_keeps_millimetres_far_from_the_origin(hdl64e):
    """A town 3 km from the world origin: the same box scan as at the origin, to < 1 mm."""
    def scan_at(offset):
        scene = scene_of([("car", box((2.0, 4.0, 4.0), "car", "car_paint", center=(offset + 13.0, 0.0, 2.0)), 7)])
        with Scanner(scene, hdl64e, threads=1) as sc:
            return sc.scan(rig.mount((offset, 0, H), (0, 0, 0))).points
    a, b = scan_at(0.0), scan_at(3000.0)
    assert len(a) == len(b) > 0
    np.testing.assert_allclose(b["range"], a["range"], atol=1e-3)


def _wall_scene():
    """A wall across the route 15 m behind the start, the ground, and a straight route along +x."""
    return scene_of([("ground", rect(-300, -300, 300, 300, 0.0, "road", "asphalt"), 0),
                     ("wall", box((1.0, 60.0, 12.0), "building", "facade_brick", center=(-15.5, 0.0, 6.0)), 2)],
                    paths=[straight_path(0.0, 250.0)])


def _with_skew(spec, on: bool):
    lidar = dataclasses.replace(spec.sensors.lidar, motion_skew=on)
    return dataclasses.replace(spec, sensors=dataclasses.replace(spec.sensors, lidar=lidar))


@pytest.mark.parametrize("skew", [True, False])
def test_motion_skew_first_and_last_columns_are_a_sweep_apart(hdl64e, test_spec, skew):
    spec = _with_skew(test_spec, skew)
    scene = _wall_scene()
    building = class_table().id("building")
    with Scanner(scene, hdl64e, threads=2) as sc:
        poses = Rig.from_spec(spec, scene).sweep_poses(0.0, hdl64e.column_time() if skew else None)
        p = sc.scan(poses).points
    assert poses.shape == ((hdl64e.azimuth_steps, 4, 4) if skew else (4, 4))
    last = hdl64e.azimuth_steps - 1
    wall = p[p["class"] == building]
    first_cols = wall[wall["column"] == 0]
    last_cols = wall[wall["column"] == last]
    rings = np.intersect1d(first_cols["ring"], last_cols["ring"])
    assert len(rings) >= 20
    x0 = first_cols["x"][np.searchsorted(first_cols["ring"], rings)]
    x1 = last_cols["x"][np.searchsorted(last_cols["ring"], rings)]
    tau = last / (hdl64e.azimuth_steps * hdl64e.rotation_hz)
    moved = spec.paths.speed_mps * tau if skew else 0.0
    # the wall face is at world x = -15; the sensor was at x = 0 for column 0 and at x = v*tau for the last
    np.testing.assert_allclose(x0, -15.0, atol=1e-3)
    np.testing.assert_allclose(x1, -15.0 - moved, atol=1e-3)
    assert moved == 0.0 or abs(moved - 0.8) < 1e-3  # 8 m/s x 0.1 s
    times = last_cols["time"]
    np.testing.assert_allclose(times, tau if skew else 0.0, atol=1e-6)
