"""Stereo disparity of a rectified pair, exact from the left depth pass: ``d = f b / Z``.

The KITTI stream's pair (:meth:`generator.world.rig.Rig.T_ego_stereo`) is rectified by
construction: same intrinsics and orientation, the right camera ``b`` metres along the left's
x axis. A left pixel whose centre ray sees a surface at distance ``depth`` has optical depth
``Z = depth * ray_z`` and lands in the right image ``d = f_x b / Z`` pixels to the left
(``u_right = u_left - d``, same row), as KITTI stereo 2015 defines disparity.

Flags: :data:`generator.motion.optical_flow.KNOWN` where the pixel sees a surface (KITTI's
``disp_occ``); :data:`~generator.motion.optical_flow.VISIBLE` where that point is also inside the
right image and not occluded there, by the right depth pass (``disp_noc``; the same occlusion
test as the flow's).
"""

from __future__ import annotations

import numpy as np

from generator.fusion.projection import Projection, visible
from generator.motion.optical_flow import KNOWN, VISIBLE, View, _rays


def baseline(T_world_left: np.ndarray, T_world_right: np.ndarray) -> float:
    """Baseline of a rectified pair, metres: the right camera's offset along the left's x axis."""
    return float((np.linalg.inv(T_world_left) @ T_world_right)[0, 3])


def disparity(left: View, right: View) -> tuple[np.ndarray, np.ndarray]:
    """Disparity of every left pixel and its flags.

    Parameters
    ----------
    left, right : View
        The pair's images (exposed together; ``right`` only for its depth and pose).

    Returns
    -------
    d : (H, W) float32
        ``f_x * b / Z`` in pixels (computed in float64), 0 where the pixel sees no surface.
    flags : (H, W) uint8
        :data:`KNOWN` | :data:`VISIBLE`.
    """
    h, w = left.shape
    b = baseline(left.T_world_camera, right.T_world_camera)
    rays = _rays(left.K.tobytes(), w, h)
    known = np.isfinite(left.depth) & (left.depth > 0)
    depth = np.where(known, left.depth, 1.0).astype(np.float64)
    Z = depth * rays[..., 2]
    d = np.where(known, left.K[0, 0] * b / Z, 0.0)
    flags = np.where(known, KNOWN, np.uint8(0)).astype(np.uint8)
    uc, vc = np.meshgrid(np.arange(w) + 0.5, np.arange(h) + 0.5)
    ur = uc - d
    hr, wr = right.shape
    inside = known & (ur >= 0) & (ur < wr) & (vc < hr)
    idx = np.flatnonzero(inside)
    if len(idx):
        X = (rays * depth[..., None]).reshape(-1, 3)[idx]
        T = np.linalg.inv(right.T_world_camera) @ left.T_world_camera  # left camera -> right camera
        Y = X @ T[:3, :3].T + T[:3, 3]
        uu, vv = ur.ravel()[idx], vc.ravel()[idx]
        proj = Projection(idx, uu, vv, np.floor(vv).astype(np.int64), np.floor(uu).astype(np.int64),
                          np.linalg.norm(Y, axis=1), Y[:, 2])
        flags.reshape(-1)[idx[visible(proj, right.depth, right.K)]] |= VISIBLE
    return d.astype(np.float32), flags
