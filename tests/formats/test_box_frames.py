"""The reader's box moves between LiDAR, ego, camera and world frames and keeps its points."""

from __future__ import annotations

import numpy as np
import pytest

from generator.detection.records import BoxRecord
from generator.errors import UserError
from generator.formats.box_frames import Box, box_of_record
from generator.world.rig import camera_extrinsics, ego_pose, mount


@pytest.fixture
def box():
    T_ego_lidar = mount((0.1, 0.0, 1.73), (0.0, 0.0, 2.0))          # a slightly turned LiDAR
    T_world_lidar = ego_pose(np.array([50.0, -20.0, 0.0]), 0.8) @ T_ego_lidar
    rec = BoxRecord(3, 0.31, 12, (12,), "car", "car", "car_0012", np.array([60.0, -15.0, 0.75]),
                    np.array([4.2, 1.8, 1.5]), 1.1, np.array([2.0, 1.0, 0.0]), np.zeros(3), True, "vehicle.moving", 99,
                    T_world_lidar)
    info = {"T_ego_lidar": T_ego_lidar.tolist(), "T_ego_camera": camera_extrinsics((0.27, 0, 1.65), (0, 0, 0)).tolist()}
    return box_of_record(rec, info)


def test_frames_round_trip_and_keep_points_inside(box, rng):
    pts = box.center + rng.uniform(-3, 3, (2000, 3))
    inside = box.contains(pts)
    assert inside.any() and (~inside).any()
    for frame in ("ego", "world", "camera"):
        moved = box.to(frame)
        T = np.linalg.inv(box.T_world(frame)) @ box.T_world("lidar")
        assert np.array_equal(moved.contains(pts @ T[:3, :3].T + T[:3, 3]), inside), frame
        back = moved.to("lidar")
        np.testing.assert_allclose(back.center, box.center, atol=1e-9)
        np.testing.assert_allclose(back.rotation, box.rotation, atol=1e-9)
        np.testing.assert_allclose(back.velocity, box.velocity, atol=1e-9)
    world = box.to("world")
    np.testing.assert_allclose(world.center, [60.0, -15.0, 0.75], atol=1e-9)
    assert world.yaw == pytest.approx(1.1) and box.yaw == pytest.approx(1.1 - 0.8 - np.radians(2.0))
    np.testing.assert_allclose(world.velocity, [2.0, 1.0, 0.0], atol=1e-9)
    assert box.to("camera").corners().shape == (8, 3)


def test_an_openlabel_box_stays_in_its_frame():
    b = Box(1, "car", np.zeros(3), np.array([0, 0, 0, 1.0]), np.ones(3), 5)
    with pytest.raises(UserError, match="OpenLABEL"):
        b.to("world")
