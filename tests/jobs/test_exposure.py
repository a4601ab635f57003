"""An image's motion record: actors' velocities in the camera's axes, the ego's motion and the camera's twist."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from generator.imaging.metadata import validate_metadata
from generator.jobs.exposure import motion_record
from generator.world import rig
from kits import motion_kit as mk


def test_motion_record_splits_ego_and_object_motion():
    """A car crossing at 10 m/s towards +y while the ego drives +x at 8 m/s: seen by a forward camera the
    car moves to the left (-x optical), the ego forward (+z optical)."""
    w = mk.world(mk.street_scene(), [mk.car(0, 301, mk.track(lambda t: (20.0, -12.0 + 10.0 * t)))],
                 mk.track(lambda t: (8.0 * t, 0.0)))
    T_ego_cam = rig.camera_extrinsics((1.0, 0.0, 1.65), (0.0, 0.0, 0.0))
    T = w.ego.T_world_ego(1.0)[0] @ T_ego_cam
    renderer = SimpleNamespace(world=w, motion_blur={"enabled": False, "shutter_s": 0.0, "method": "none"})
    instance = np.zeros((4, 4), np.uint32)
    instance[1, 1] = 301
    rec = motion_record(renderer, 1.0, instance, T, T_ego_cam)
    (car,) = rec["actors"]
    np.testing.assert_allclose(car["velocity_camera_mps"], [-10.0, 0.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(rec["ego"]["velocity_ego_mps"], [8.0, 0.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(rec["ego"]["camera"]["velocity_mps"], [0.0, 0.0, 8.0], atol=1e-6)
    assert rec["ego"]["yaw_rate_rad_s"] == 0.0 and abs(rec["ego"]["speed_mps"] - 8.0) < 1e-9
    schema = {"motion": rec}
    problems = [p for p in validate_metadata(schema) if "motion" in p]
    assert problems == []
