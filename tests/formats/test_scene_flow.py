"""The scene-flow side file: four float32 per point, read back exactly; bad files are one-line errors."""

from __future__ import annotations

import numpy as np
import pytest

from generator.errors import UserError
from generator.formats.scene_flow import poses_at, read_scene_flow, write_scene_flow
from generator.world.rig import pose


def test_round_trip(tmp_path, rng):
    obj = rng.normal(size=(100, 3)).astype(np.float32)
    flag = rng.integers(0, 3, 100).astype(np.uint8)
    write_scene_flow(tmp_path, "000004", obj, flag)
    raw = np.fromfile(tmp_path / "scene_flow" / "000004.bin", "<f4").reshape(-1, 4)
    np.testing.assert_array_equal(raw[:, :3], obj)
    np.testing.assert_array_equal(raw[:, 3], flag)
    got_obj, got_flag = read_scene_flow(tmp_path, 4, 100)
    np.testing.assert_array_equal(got_obj, obj)
    np.testing.assert_array_equal(got_flag, flag)
    assert read_scene_flow(tmp_path, 5, 100) is None


def test_bad_files(tmp_path):
    write_scene_flow(tmp_path, "000000", np.zeros((10, 3), np.float32), np.zeros(10, np.uint8))
    with pytest.raises(UserError, match="10 rows but the scan has 11 points"):
        read_scene_flow(tmp_path, 0, 11)
    write_scene_flow(tmp_path, "000001", np.zeros((2, 3), np.float32), np.array([0, 7], np.uint8))
    with pytest.raises(UserError, match="flag"):
        read_scene_flow(tmp_path, 1, 2)


def test_poses_at_interpolates_between_knots():
    T = np.stack([pose(0, 0, 0, yaw=0.0), pose(2.0, 1.0, 0, yaw=0.4)])
    mid = poses_at(np.array([0.05]), np.array([0.0, 0.1]), T)[0]
    np.testing.assert_allclose(mid, pose(1.0, 0.5, 0, yaw=0.2), atol=1e-12)
