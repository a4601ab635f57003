"""OpenLABEL with motion: per-frame velocity / acceleration / moving of actors on a synthetic world.

Velocities must equal the central finite differences of the cuboid centres of the
neighbouring frames (in the fixed ``odom`` frame) within ``max|a| * 0.1 s``: the written
velocity is the mean over +-0.05 s (the track spacing), the frame difference the mean over
+-0.1 s (see :mod:`generator.formats.openlabel_motion`).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from generator.detection import subjects
from generator.formats import openlabel_motion as om
from generator.formats.openlabel import build_openlabel, validate_openlabel
from generator.jobs.boxes import SweepFrame
from generator.world import rig
from generator.world.actors import MOVING_THRESHOLD_MPS, Actor, Track, TrackTrajectory, World
from generator.world.scene import OrientedBox, SceneObject

DT = 0.05
N_SWEEPS = 21


def _track(f, t1=3.0) -> Track:
    """Track sampled every DT from 0 (and a bit before/after) of ``f(t) -> (x, y)``; yaw along the motion."""
    t = np.arange(0.0, t1 + DT / 2, DT)
    xy = np.array([f(v) for v in t])
    d = np.gradient(xy, DT, axis=0)
    speed = np.linalg.norm(d, axis=1)
    yaw = np.where(speed > 1e-9, np.arctan2(d[:, 1], d[:, 0]), 0.3)
    return Track(0.0, DT, np.c_[xy, np.zeros(len(t))], np.unwrap(yaw))


def _actor(uid, name, cls, track, iid):
    return Actor(uid, name, "car" if cls == "car" else cls, cls, iid, "p", (4.2, 1.8, 1.5), (1.3, 0.1, 0.75), track)


@pytest.fixture(scope="module")
def world():
    ego = _track(lambda t: (5.0 * t, 0.4 * t * t))  # accelerating sideways: the ego turns
    actors = [
        _actor(0, "actor_car_0000", "car", _track(lambda t: (10 + 2 * t + 0.75 * t * t, 3 + 0.2 * t * t)), 101),
        _actor(1, "actor_car_0001", "car", _track(lambda t: (30.0, -4.0)), 102),  # waiting at a stop line
        _actor(2, "actor_person_0002", "person", _track(lambda t: (8 + 0.2 * t, 6.0)), 103),  # below threshold
        _actor(3, "actor_person_0003", "person", _track(lambda t: (8 + 1.4 * t, -6.0)), 104),
    ]
    return World(None, actors, {}, {}, TrackTrajectory(ego, np.zeros(len(ego.yaw))), 3.0)


@pytest.fixture(scope="module")
def doc(world):
    box = OrientedBox((20.0, 8.0, 0.75), (4.0, 1.8, 1.5), 0.5)
    parked = SceneObject(0, "car_0007", "car", "car", 7, "p", np.eye(4), box, attrs={"placement": "parked"})
    subs = subjects(SimpleNamespace(objects=[parked], prototypes={}), world)
    times = [rig.Rig.sweep_time(j) for j in range(N_SWEEPS)]
    T_cam = rig.camera_extrinsics((1.0, 0.0, 1.6), (0.0, 0.0, 0.0))
    frames = [SweepFrame(j, t, world.ego.T_world_ego(t)[0], T_cam if j % 5 == 0 else None,
                         j // 5 if j % 5 == 0 else None) for j, t in enumerate(times)]
    uris = [{"lidar": f"velodyne/{j:06d}.bin", **({"camera": f"images/{j // 5:06d}.exr"} if j % 5 == 0 else {})}
            for j in range(N_SWEEPS)]
    counts = [{7: 50, 101: 80, 102: 40, 103: 20, 104: 20} for _ in times]
    d = build_openlabel(subjects=subs, frames=frames, times=times, counts=counts, min_points=5,
                        T_ego_lidar=rig.mount((0, 0, 1.73), (0, 0, 0)), T_ego_camera_nominal=T_cam,
                        K=rig.intrinsics(90, 64, 48), width=64, height=48,
                        streams={"camera": {"uri": "images/", "description": "cam"},
                                 "lidar": {"uri": "velodyne/", "description": "lidar"}},
                        frame_uris=uris, info={"scene": "synthetic"})
    return d["openlabel"]


def _centres_odom(ol, uid: str) -> np.ndarray:
    """(N_SWEEPS, 3) cuboid centres of object ``uid`` in odom (vehicle cuboid through each frame's ego transform)."""
    out = []
    for j in range(N_SWEEPS):
        f = ol["frames"][str(j)]
        tr = f["frame_properties"]["transforms"]["vehicle-iso8855_to_odom"]["transform_src_to_dst"]
        T = np.asarray(tr["matrix4x4"]).reshape(4, 4)
        c = om.object_data(f["objects"][uid]["object_data"], "box3d", "cuboid")["val"][:3]
        out.append(T[:3, :3] @ np.asarray(c) + T[:3, 3])
    return np.array(out)


def test_schema_valid(doc):
    assert validate_openlabel({"openlabel": doc}) == []


def test_velocity_is_finite_difference_of_cuboid_centres(doc, world):
    for a in world.actors:
        c = _centres_odom(doc, str(a.instance_id))
        fd = (c[2:] - c[:-2]) / (2 * rig.SWEEP_PERIOD_S)
        # bound on |a| from the samples (second differences), then the window-mean tolerance
        acc = np.abs(np.diff(a.track.xyz, 2, axis=0)).max() / DT ** 2
        tol = acc * rig.SWEEP_PERIOD_S + 1e-4
        for j in range(1, N_SWEEPS - 1):
            od = doc["frames"][str(j)]["objects"][str(a.instance_id)]["object_data"]
            v = np.asarray(om.object_data(od, "velocity", "vec")["val"])
            assert om.object_data(od, "velocity", "vec")["coordinate_system"] == "odom"
            np.testing.assert_allclose(v, fd[j - 1], atol=tol, err_msg=f"{a.name} frame {j}")
            assert om.object_data(od, "speed", "num")["val"] == pytest.approx(np.linalg.norm(v), abs=1e-5)
    # the accelerating car: the analytic acceleration (1.5, 0.4) up to the turning box offset
    od = doc["frames"]["10"]["objects"]["101"]["object_data"]
    np.testing.assert_allclose(om.object_data(od, "acceleration", "vec")["val"][:2], [1.5, 0.4], atol=0.15)


def test_velocity_is_over_ground_in_odom(doc):
    """A parked car reads 0 although the ego moves and turns; the frame-0 vehicle axes are odom's."""
    for j in range(N_SWEEPS):
        od = doc["frames"][str(j)]["objects"]["7"]["object_data"]
        assert om.object_data(od, "velocity", "vec")["val"] == [0.0, 0.0, 0.0]
        assert om.object_data(od, "moving", "boolean")["val"] is False


def test_moving_flag_is_the_lidar_rule(doc, world):
    seen = set()
    for j in range(N_SWEEPS):
        t = rig.Rig.sweep_time(j)
        moving = world.moving(t)
        for a, m in zip(world.actors, moving, strict=True):
            data = doc["frames"][str(j)]["objects"][str(a.instance_id)]["object_data"]
            flag = om.object_data(data, "moving", "boolean")["val"]
            assert flag == bool(m)
            assert flag == (np.linalg.norm(a.track.velocity(t)[0, :2]) > MOVING_THRESHOLD_MPS)
            seen.add(flag)
    assert seen == {True, False}


def test_uids_stable_and_disjoint(doc, world):
    assert set(doc["objects"]) == {"7", "101", "102", "103", "104"}
    for a in world.actors:
        o = doc["objects"][str(a.instance_id)]
        assert o["name"] == a.name and o["type"] == a.cls
        assert o["frame_intervals"] == [{"frame_start": 0, "frame_end": N_SWEEPS - 1}]
    for j in range(N_SWEEPS):
        assert set(doc["frames"][str(j)]["objects"]) == set(doc["objects"])


def test_timestamps_and_camera_only_with_images(doc):
    for j in range(N_SWEEPS):
        fp = doc["frames"][str(j)]["frame_properties"]
        assert fp["timestamp"] == pytest.approx(0.1 * j)
        assert all(s["stream_properties"]["sync"]["timestamp"] == fp["timestamp"] for s in fp["streams"].values())
        assert ("camera" in fp["streams"]) == (j % 5 == 0)
        assert ("camera_to_vehicle-iso8855" in fp["transforms"]) == (j % 5 == 0)
