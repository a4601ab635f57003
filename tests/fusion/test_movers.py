"""Fusion with movers: actor points de-skewed by their own motion, a semantic map without movers.

A synthetic world: the ego drives along x at 8 m/s; one car crosses at 10 m/s, one turns on a
circle, one waits. Points are sampled on the cars' surfaces at their firing instants and
written in the LiDAR frame of that instant (as the ``.bin`` files hold them).
"""

from __future__ import annotations

import numpy as np
import pytest

from generator.formats.openlabel import cuboid_contains, cuboid_val
from generator.fusion import movers
from generator.fusion.dataset import deskewed
from generator.fusion.projection import transform
from generator.fusion.semantic_map import VoxelMap
from generator.world import rig
from generator.world.actors import Actor, Track, TrackTrajectory, World

DT = 0.05
T_EGO_LIDAR = rig.mount((0.0, 0.0, 1.73), (0.0, 0.0, 0.0))


def _track(f, t1=2.0) -> Track:
    t = np.arange(0.0, t1 + DT / 2, DT)
    xy = np.array([f(v) for v in t])
    d = np.gradient(xy, DT, axis=0)
    yaw = np.where(np.linalg.norm(d, axis=1) > 1e-9, np.arctan2(d[:, 1], d[:, 0]), 0.0)
    return Track(0.0, DT, np.c_[xy, np.zeros(len(t))], np.unwrap(yaw))


@pytest.fixture(scope="module")
def world():
    ego = _track(lambda t: (8.0 * t, 0.0))
    size, centre = (4.2, 1.8, 1.5), (1.3, 0.0, 0.75)
    actors = [Actor(0, "actor_car_0000", "car", "car", 201, "p", size, centre, _track(lambda t: (12.0, -15 + 10 * t))),
              Actor(1, "actor_car_0001", "car", "car", 202, "p", size, centre,
                    _track(lambda t: (20 + 8 * np.cos(1.2 * t), 8 * np.sin(1.2 * t)))),
              Actor(2, "actor_car_0002", "car", "car", 203, "p", size, centre, _track(lambda t: (25.0, 6.0)))]
    return World(None, actors, {}, {}, TrackTrajectory(ego, 8.0 * np.arange(len(ego.yaw)) * DT), 2.0)


def _scan(world, j: int, rng):
    """A sweep of points on every actor's box surface (and some ground), LiDAR frame at each firing time."""
    t0 = rig.Rig.sweep_time(j)
    pts, inst, tau, sem = [], [], [], []
    for a in world.actors:
        n = 200
        tt = np.sort(rng.uniform(0, rig.SWEEP_PERIOD_S, n))
        local = (rng.uniform(-0.5, 0.5, (n, 3))) * np.asarray(a.size)
        face = rng.integers(0, 3, n)
        local[np.arange(n), face] = np.sign(local[np.arange(n), face]) * np.asarray(a.size)[face] / 2  # on a face
        local += np.asarray(a.box_center)
        T_wa = a.track.pose(t0 + tt)
        pw = np.einsum("nij,nj->ni", T_wa[:, :3, :3], local) + T_wa[:, :3, 3]
        pts.append(pw), inst.append(np.full(n, a.instance_id)), tau.append(tt)
        sem.append(np.full(n, 252 if a.track.speed(t0)[0] > 0.3 else 10))
    ground_t = rng.uniform(0, rig.SWEEP_PERIOD_S, 100)
    pts.append(np.c_[rng.uniform(0, 40, 100), rng.uniform(-10, 10, 100), np.zeros(100)])
    inst.append(np.zeros(100, np.int64)), tau.append(ground_t), sem.append(np.full(100, 40))
    pw, inst, tau, sem = (np.concatenate(v) for v in (pts, inst, tau, sem))
    T_wl = world.ego.T_world_ego(t0 + tau) @ T_EGO_LIDAR
    raw = np.einsum("nji,nj->ni", T_wl[:, :3, :3], pw - T_wl[:, :3, 3])  # into each firing instant's LiDAR frame
    knots = world.ego.knot_offsets(t0, rig.SWEEP_PERIOD_S)
    return {"xyz": raw, "times": tau, "instance": inst, "semantic": sem, "t_sweep": t0,
            "sweep_times": knots, "sweep_poses": world.ego.T_world_ego(t0 + knots) @ T_EGO_LIDAR,
            "T_world_lidar_start": (world.ego.T_world_ego(t0) @ T_EGO_LIDAR)[0], "world_xyz": pw}


@pytest.mark.parametrize("j", [0, 3, 7])
def test_actor_points_land_on_the_car_at_the_image_time(world, j):
    scan = _scan(world, j, np.random.default_rng(j))
    t_img = scan["t_sweep"]  # the image is exposed at the sweep start
    T_lw = rig.invert(scan["T_world_lidar_start"])
    sensor_only = deskewed(scan, True)
    both = deskewed(scan, True, movers.actor_poses(world))
    for a in world.actors:
        idx = np.flatnonzero(scan["instance"] == a.instance_id)
        box = cuboid_val(a.box(t_img), T_lw)  # the car at the image time, LiDAR frame of the sweep start
        assert cuboid_contains(box, both[idx], margin=1e-4).all()  # cuboid values are rounded to 1e-6
        # on the surface: some local coordinate is at the half-size
        v = np.asarray(box)
        from scipy.spatial.transform import Rotation

        local = (both[idx] - v[:3]) @ Rotation.from_quat(v[3:7]).as_matrix()
        assert np.allclose(np.max(np.abs(local) / (v[7:10] / 2), axis=1), 1.0, atol=1e-4)
        if a.track.speed(t_img)[0] > 1.0:  # the sensor de-skew alone leaves them smeared
            assert not cuboid_contains(box, sensor_only[idx], margin=0.05).all()
        else:
            np.testing.assert_allclose(both[idx], sensor_only[idx], atol=1e-9)
    ground = scan["instance"] == 0
    np.testing.assert_array_equal(both[ground], sensor_only[ground])
    # sensor de-skew alone is exact for static points
    np.testing.assert_allclose(transform(scan["T_world_lidar_start"], both[ground]), scan["world_xyz"][ground],
                               atol=1e-9)


def test_without_times_every_point_fired_at_the_sweep_start(world):
    scan = _scan(world, 2, np.random.default_rng(5))
    out = movers.deskew_movers(scan["xyz"], scan["instance"], None, scan["t_sweep"], scan["t_sweep"],
                               scan["T_world_lidar_start"], movers.actor_poses(world))
    np.testing.assert_allclose(out, scan["xyz"], atol=1e-12)  # moved by identity transforms


def test_static_mask_drops_moving_labels_and_actors():
    sem = np.array([40, 252, 254, 259, 10, 10, 260, 251])
    inst = np.array([0, 201, 5, 7, 203, 9, 0, 0])
    np.testing.assert_array_equal(movers.static_mask(sem, inst), [1, 0, 0, 0, 1, 1, 1, 1])
    np.testing.assert_array_equal(movers.static_mask(sem, inst, [203]), [1, 0, 0, 0, 0, 1, 1, 1])
    np.testing.assert_array_equal(movers.is_moving_label((3 << 16) | 252), True)


def test_semantic_map_has_no_moving_points(world):
    vm = VoxelMap(0.2)
    actors = [a.instance_id for a in world.actors]
    for j in range(8):
        scan = _scan(world, j, np.random.default_rng(100 + j))
        xyz = transform(scan["T_world_lidar_start"], deskewed(scan, True, movers.actor_poses(world)))
        native = np.where(scan["instance"] > 0, 16, 1)  # car / road
        dropped = vm.add_static(xyz, native, scan["semantic"], scan["instance"], actors)
        assert dropped == int((scan["instance"] > 0).sum())
    xyz, label, count = vm.voxels()
    assert set(label.tolist()) == {1} and count.sum() == vm.points == 8 * 100
    assert vm.dropped == 8 * 600
    assert np.allclose(xyz[:, 2], 0.0, atol=1e-6)  # only the ground is left
