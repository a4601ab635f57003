"""The world's motion between instants: actor displacements, the ego's velocity and yaw rate, a camera's twist."""

from __future__ import annotations

import numpy as np
import pytest

from generator.world import rig
from generator.world.kinematics import camera_motion, ego_motion, movers
from kits import motion_kit as mk

R, V = 20.0, 8.0  # a circle of 20 m at 8 m/s: yaw rate 0.4 rad/s


@pytest.fixture(scope="module")
def circling():
    ego = mk.track(lambda t: (R * np.sin(V * t / R), R - R * np.cos(V * t / R)), 6.0)
    return mk.world(None, [mk.car(0, 300, mk.track(lambda t: (5.0 + 3.0 * t, 1.0), 6.0))], ego, 6.0)


def test_ego_motion_on_a_circle(circling):
    m = ego_motion(circling.ego, 2.0)
    assert m["yaw_rate_rad_s"] == pytest.approx(V / R, rel=1e-3)
    assert m["speed_mps"] == pytest.approx(V, rel=1e-3)
    np.testing.assert_allclose(m["velocity_ego_mps"], [V, 0.0, 0.0], atol=0.02)


def test_camera_twist_of_a_forward_camera_on_a_turning_ego(circling):
    """A camera 1 m ahead of the ego origin moves at (v, w * 1 m) in ego axes; in optical axes (x right,
    y down, z forward) that is (-w, 0, v), and the turn (about ego z, up) is about optical -y."""
    w = V / R
    m = camera_motion(circling.ego, rig.camera_extrinsics((1.0, 0.0, 1.65), (0.0, 0.0, 0.0)), 2.0)
    np.testing.assert_allclose(m["velocity_mps"], [-w * 1.0, 0.0, V], atol=0.02)
    np.testing.assert_allclose(m["angular_velocity_rad_s"], [0.0, -w, 0.0], atol=1e-3)


def test_mover_displacement_and_box(circling):
    (m,) = movers(circling, 1.0, 1.5)
    p = np.array([[8.0 + 1.0, 1.2, 0.5]])  # on the car (its origin at x = 8 at t = 1)
    moved = p @ m.M[:3, :3].T + m.M[:3, 3]
    np.testing.assert_allclose(moved, p + [1.5, 0.0, 0.0], atol=1e-9)
    assert m.inside(p, 0.0).all() and not m.inside(p + [5.0, 0, 0], 0.0).any()
    assert movers(None, 0.0, 1.0) == [] and movers(mk.world(None, [], circling.ego.track), 0.0, 1.0) == []
