"""LiDAR scene flow of real sweeps (the scanner, motion skew on): points land on the next sweep's surfaces,
the static town moves by the ego's motion alone, the reader's ego flow is the writer's, flags judge right."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree

from generator.formats.scene_flow import ego_flow
from generator.lidar.scan import Scanner
from generator.lidar.sensors import load_preset
from generator.motion.scene_flow import GONE, HIDDEN, SEEN, SceneFlow, next_sweep_flags, scene_flow
from generator.world import rig as R
from kits import motion_kit as mk

DT = R.SWEEP_PERIOD_S
MOVERS = (301, 302)


def _rig(world):
    return R.Rig(0, (0.0, 0.0, 1.65), (0.0, 0.0, 0.0), 90.0, (0.0, 0.0, 0.0), R.mount((0.0, 0.0, 1.73), (0, 0, 0)),
                 10.0, 0.54, world.ego)


@pytest.fixture(scope="module")
def sweeps():
    """The ego at 8 m/s down the street; a car crossing 20 m ahead at 10 m/s, one ahead at 12 m/s."""
    actors = [mk.car(0, 301, mk.track(lambda t: (26.0, -15.0 + 10.0 * t))),
              mk.car(1, 302, mk.track(lambda t: (14.0 + 12.0 * t, 3.0)))]
    w = mk.world(mk.street_scene(), actors, mk.track(lambda t: (8.0 * t, 0.0)))
    rig, sensor = _rig(w), load_preset("hdl64e")
    with Scanner(w.scene, sensor, world=w, threads=2) as sc:
        pts = [sc.sweep(rig, R.Rig.sweep_time(j), True).points for j in (12, 13)]
    flows = SceneFlow.for_rig(rig, w.actors, sensor, True, DT)
    obj, flag = flows.sweep(pts[0], pts[1], R.Rig.sweep_time(12))
    return w, rig, sensor, pts, obj, flag


def _xyz(p):
    return np.stack([p["x"], p["y"], p["z"]], -1).astype(np.float64)


def test_moving_points_land_on_the_next_sweeps_surface(sweeps):
    """Per moving car: the median distance from a point moved by its flow (with ego motion) to the nearest
    next-sweep point of the same car is at most the car's point spacing in that sweep; unmoved it is not."""
    w, rig, sensor, (p0, p1), obj, _ = sweeps
    xyz0, xyz1 = _xyz(p0), _xyz(p1)
    _, ego = scene_flow(xyz0, p0["instance"], p0["column"], sensor.column_time(), R.Rig.sweep_time(12), DT, rig,
                        w.actors)
    for iid in MOVERS:
        a, b = p0["instance"] == iid, p1["instance"] == iid
        assert a.sum() > 50 and b.sum() > 50
        spacing = np.median(cKDTree(xyz1[b]).query(xyz1[b], k=2)[0][:, 1])
        moved = np.median(cKDTree(xyz1[b]).query(xyz0[a] + ego[a])[0])
        still = np.median(cKDTree(xyz1[b]).query(xyz0[a])[0])
        assert moved <= spacing < still, (iid, moved, spacing, still)
        assert np.abs(obj[a]).max() > 0.5  # 10-12 m/s x 0.1 s


def test_static_points_move_by_the_ego_motion_alone(sweeps):
    w, rig, sensor, (p0, _), obj, _ = sweeps
    static = ~np.isin(p0["instance"], MOVERS)
    assert (obj[static] == 0).all()
    xyz = _xyz(p0)
    _, ego = scene_flow(xyz, p0["instance"], p0["column"], sensor.column_time(), R.Rig.sweep_time(12), DT, rig,
                        w.actors)
    t = R.Rig.sweep_time(12) + sensor.column_time()[p0["column"]]
    Tp, Tq = rig.T_world_lidar(t), rig.T_world_lidar(t + DT)
    world = np.einsum("nij,nj->ni", Tp[:, :3, :3], xyz) + Tp[:, :3, 3]
    expected = np.einsum("nji,nj->ni", Tq[:, :3, :3], world - Tq[:, :3, 3]) - xyz
    np.testing.assert_allclose(ego[static], expected[static], atol=1e-4)
    assert np.abs(expected[static][:, 0]).mean() > 0.7  # 8 m/s x 0.1 s, mostly along x


def test_the_readers_ego_flow_from_the_recorded_poses_is_the_writers(sweeps):
    w, rig, sensor, (p0, _), obj, _ = sweeps
    xyz = _xyz(p0)
    _, ego = scene_flow(xyz, p0["instance"], p0["column"], sensor.column_time(), R.Rig.sweep_time(12), DT, rig,
                        w.actors)
    records = [rig.sweep_record(R.Rig.sweep_time(j), sensor.period_s) for j in (12, 13)]
    records = [{"t_s": np.array(r["t_s"]), "T_world_lidar": np.array(r["T_world_lidar"])} for r in records]
    got = ego_flow(xyz, obj, p0["time"], records[0], records[1])
    np.testing.assert_allclose(got, ego, atol=2e-4)


def test_flags_seen_hidden_gone(sweeps):
    """Against a wall of returns 10 m ahead: a point 20 m ahead is hidden, 5 m ahead seen; beyond the
    range, above the highest beam or right at the sensor it is gone."""
    _, _, sensor, _, _, _ = sweeps
    _, dirs, _ = sensor.local_rays()
    ahead = dirs[np.abs(np.arctan2(dirs[..., 1], dirs[..., 0])) < 0.2]
    wall = ahead * 10.0 + [0.0, 0.0, 0.18]
    el = np.radians(-5.0)
    d = np.array([np.cos(el), 0.0, np.sin(el)])
    pts = np.array([d * 20 + [0, 0, 0.18], d * 5 + [0, 0, 0.18], d * 150, [5.0, 0.0, 4.0], [0.01, 0.0, 0.0]])
    assert list(next_sweep_flags(pts, wall, sensor)) == [HIDDEN, SEEN, GONE, GONE, GONE]


def test_flags_on_a_real_sweep(sweeps):
    """Most points are seen at the next sweep; the seen ones have a next-sweep return close by far more
    often than the hidden ones."""
    _, _, _, (p0, p1), obj, flag = sweeps
    w, rig, sensor = sweeps[0], sweeps[1], sweeps[2]
    xyz0, xyz1 = _xyz(p0), _xyz(p1)
    _, ego = scene_flow(xyz0, p0["instance"], p0["column"], sensor.column_time(), R.Rig.sweep_time(12), DT, rig,
                        w.actors)
    dist = cKDTree(xyz1).query(xyz0 + ego)[0]
    near = dist < np.maximum(0.3, 0.02 * np.linalg.norm(xyz0, axis=1))
    assert (flag == SEEN).mean() > 0.9
    assert near[flag == SEEN].mean() > 0.9
    assert near[flag == HIDDEN].mean() < near[flag == SEEN].mean() - 0.2
