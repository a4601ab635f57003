"""Per-sweep box records: the instant the LiDAR sees a box, the point threshold, frames (issue 26, items 1, 8)."""

from __future__ import annotations

import numpy as np
import pytest

from generator.detection import SweepClock, boxes_at, instance_counts, sweep_boxes
from generator.detection.frames import box_in_frame, corners, kitti_rotation_y, points_in_box, yaw_in
from generator.detection.subjects import Subject
from generator.world.rig import camera_extrinsics, ego_pose, mount
from generator.world.scene import OrientedBox

CLOCK = SweepClock(np.pi, True, 0.1)   # starts facing back, turns clockwise (the HDL-64E preset)


def _static(track_id, center, yaw=0.0, ids=None):
    return Subject(track_id, ids or (track_id,), "car", "car", f"car_{track_id}", True, "vehicle", False, "parked", (),
                   OrientedBox(center, (4.0, 2.0, 1.5), yaw))


def _lidar(t):
    return ego_pose(np.array([5.0 * t, 0.0, 0.0]), 0.0) @ mount((0, 0, 1.73), (0, 0, 0))


def test_the_clock_fires_back_left_front_right():
    assert [CLOCK.offset(a) for a in (np.pi, np.pi / 2, 0.0, -np.pi / 2)] == pytest.approx([0.0, 0.025, 0.05, 0.075])
    assert SweepClock(0.0, False, 0.1).offset(np.pi / 2) == pytest.approx(0.025)


def test_a_box_is_described_when_the_beam_passes_it():
    ahead, left = _static(1, (30.0, 0.0, 0.75)), _static(2, (0.0, 20.0, 0.75))
    recs = sweep_boxes([ahead, left], 3, 1.0, _lidar, {1: 5, 2: 5}, CLOCK)
    assert recs[0].t == pytest.approx(1.05, abs=1e-6)
    # left of the LiDAR at the sweep start; the LiDAR moves on 0.125 m while the beam turns, so a bit behind
    az = np.arctan2(20.0, -5.0 * recs[1].t)
    assert recs[1].t == pytest.approx(1.0 + CLOCK.offset(az), abs=1e-4)
    np.testing.assert_allclose(recs[0].T_world_lidar, _lidar(recs[0].t))
    np.testing.assert_allclose(recs[0].lidar()["center"], [30.0 - 5.0 * recs[0].t, 0.0, 0.75 - 1.73], atol=1e-9)
    without = sweep_boxes([ahead], 3, 1.0, _lidar, {1: 5})
    assert without[0].t == 1.0


def test_points_decide_which_boxes_a_sweep_has():
    subs = [_static(1, (10.0, 0, 0.75)), _static(2, (20.0, 0, 0.75), ids=(2, 7)), _static(3, (30.0, 0, 0.75))]
    counts = instance_counts(np.array([0, 0, 1, 2, 7, 7, 9], np.uint16))
    assert counts == {1: 1, 2: 1, 7: 2, 9: 1}
    recs = sweep_boxes(subs, 0, 0.0, _lidar, counts)
    assert [(r.track_id, r.num_lidar_pts) for r in recs] == [(1, 1), (2, 3)]       # >= 1 point, parts summed
    assert [r.track_id for r in sweep_boxes(subs, 0, 0.0, _lidar, counts, min_points=2)] == [2]
    assert [r.track_id for r in sweep_boxes(subs, 0, 0.0, _lidar, counts, min_points=0)] == [1, 2, 3]
    assert all(r.num_lidar_pts == -1 and r.t == 0.5 for r in boxes_at(subs, 0.5, _lidar))


def test_frames_move_boxes_and_points_alike(rng):
    center, yaw, size = np.array([12.0, -3.0, 0.8]), 0.7, np.array([4.5, 1.9, 1.6])
    pts = center + rng.uniform(-3, 3, (3000, 3))
    inside = points_in_box(pts, center, size, box_in_frame(center, yaw, np.eye(4))[1])
    assert inside.any() and (~inside).any()
    T_cam = np.linalg.inv(ego_pose(np.array([2.0, 1.0, 0.0]), -0.3) @ camera_extrinsics((1.0, 0.0, 1.6), (0, 0, 0)))
    c, R = box_in_frame(center, yaw, T_cam)
    moved = pts @ T_cam[:3, :3].T + T_cam[:3, 3]
    assert np.array_equal(points_in_box(moved, c, size, R), inside)
    # the KITTI angle: the length axis in the camera frame is (cos ry, 0, -sin ry)
    ry = kitti_rotation_y(R)
    np.testing.assert_allclose(R[:, 0], [np.cos(ry), 0.0, -np.sin(ry)], atol=1e-12)
    # in an upright frame the yaw is the world yaw minus the frame's heading
    T_ego = np.linalg.inv(ego_pose(np.array([2.0, 1.0, 0.0]), -0.3))
    assert yaw_in(box_in_frame(center, yaw, T_ego)[1]) == pytest.approx(1.0)
    assert corners(c, size, R).shape == (8, 3)
