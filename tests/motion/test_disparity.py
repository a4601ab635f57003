"""Stereo disparity: exactly f b / Z of the left depth pass; the right view's occlusion against a ray cast."""

from __future__ import annotations

import numpy as np
import pytest

from generator.lidar.caster import EmbreeCaster
from generator.motion.disparity import baseline, disparity
from generator.world import rig
from kits import motion_kit as mk

W, H = 160, 96
K = rig.intrinsics(90.0, W, H)
B = 0.54


@pytest.fixture(scope="module")
def pair():
    w = mk.world(mk.street_scene(), [], mk.track(lambda t: (0.0, 0.0)))
    left = rig.camera_extrinsics((8.0, 1.5, 1.65), (0.0, 0.0, 0.0))
    shift = np.eye(4)
    shift[0, 3] = B
    caster = mk.Caster(w)
    (lv, _), (rv, _) = caster.view(left, K, W, H, 0.0), caster.view(left @ shift, K, W, H, 0.0)
    return w, lv, rv


def test_disparity_is_f_b_over_z_of_the_depth_pass(pair):
    _, lv, rv = pair
    d, flags = disparity(lv, rv)
    assert baseline(lv.T_world_camera, rv.T_world_camera) == pytest.approx(B, abs=1e-12)
    ray_z = rig.pixel_rays(K, W, H)[..., 2]
    known = np.isfinite(lv.depth)
    Z = lv.depth.astype(np.float64) * ray_z
    np.testing.assert_array_equal(d[known], (K[0, 0] * B / Z[known]).astype(np.float32))
    assert (d[~known] == 0).all() and not flags[~known].any() and (flags[known] & 1).all()


def test_visible_means_the_right_camera_sees_that_point(pair):
    """A left pixel is ``VISIBLE`` iff a ray from the right camera towards its surface point reaches it
    (nothing nearer in the way) inside the right image; checked with an independent ray cast."""
    w, lv, rv = pair
    d, flags = disparity(lv, rv)
    known = np.isfinite(lv.depth)
    X = (rig.pixel_rays(K, W, H) * np.where(known, lv.depth, 0.0)[..., None])[known]
    Xw = X @ lv.T_world_camera[:3, :3].T + lv.T_world_camera[:3, 3]
    c = rv.T_world_camera[:3, 3]
    to = Xw - c
    dist = np.linalg.norm(to, axis=1)
    caster = EmbreeCaster.from_scene(w.scene)
    hit, _ = caster.intersect(np.repeat(c[None], len(to), 0), (to / dist[:, None]).astype(np.float32), 1e4)
    u_right = (np.arange(W) + 0.5)[None, :].repeat(H, 0)[known] - d[known]
    seen = (hit > dist - 0.05) & (u_right >= 0)
    ours = (flags[known] & 2) > 0
    assert (~seen).sum() > 100  # the pole, the parked car and the frame's edge hide something
    assert (ours == seen).mean() > 0.99
