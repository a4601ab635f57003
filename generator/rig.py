"""Sensor rig geometry: the frames every sensor consumer agrees on.

Frames (all right-handed, metres):

* **world**: z up, x east, y north; road surface at z = 0.
* **ego** (ISO 8855 vehicle frame): x forward, y left, z up; origin on the ground
  below the LiDAR. ``T_world_ego`` comes from a path sample (position, heading).
* **lidar**: axes like ego (x forward, y left, z up), mounted at ``sensors.lidar.xyz_m``.
  Points in ``.bin`` files are in this frame.
* **camera** (optical, OpenCV/KITTI): x right, y down, z forward. ``K`` projects
  camera-frame points to pixels: ``u = fx x/z + cx``, ``v = fy y/z + cy`` with the
  pixel origin at the top-left corner of the top-left pixel (pixel centres at +0.5).

A transform ``T_a_b`` is a (4, 4) float64 matrix mapping points in frame b to frame a.
"""

from __future__ import annotations

import math

import numpy as np

from assets_procedural.mesh import pose

#: Rotation taking optical-frame vectors (x right, y down, z forward) to body axes
#: (x forward, y left, z up): columns are the optical axes written in the body frame.
R_BODY_OPTICAL = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])


def ego_pose(position: np.ndarray, heading: float) -> np.ndarray:
    """``T_world_ego`` for an ego at ``position`` ((3,) world, metres) facing ``heading`` (rad)."""
    return pose(float(position[0]), float(position[1]), float(position[2]), yaw=float(heading))


def mount(xyz_m, rpy_deg) -> np.ndarray:
    """``T_ego_sensor`` of a body-axes sensor mounted at ``xyz_m`` with roll, pitch, yaw in degrees."""
    r, p, y = (math.radians(a) for a in rpy_deg)
    return pose(*xyz_m, yaw=y, pitch=p, roll=r)


def camera_extrinsics(xyz_m, rpy_deg, jitter_rad=(0.0, 0.0, 0.0)) -> np.ndarray:
    """``T_ego_camera`` (optical camera frame) for a camera mount plus a per-frame jitter.

    Parameters
    ----------
    xyz_m : (3,) float
        Camera position in the ego frame, metres.
    rpy_deg : (3,) float
        Mounting roll, pitch, yaw in degrees (body axes).
    jitter_rad : (3,) float
        Extra (yaw, pitch, roll) of this frame in radians: yaw turns the camera left,
        pitch tilts it down (positive pitch about body y looks down), roll tilts it
        about the viewing axis.
    """
    yaw, pitch, roll = jitter_rad
    t = mount(xyz_m, rpy_deg) @ pose(yaw=yaw, pitch=pitch, roll=roll)
    out = t.copy()
    out[:3, :3] = t[:3, :3] @ R_BODY_OPTICAL
    return out


def intrinsics(hfov_deg: float, width: int, height: int) -> np.ndarray:
    """(3, 3) float64 pinhole ``K`` with square pixels and the principal point at the centre."""
    f = (width / 2.0) / math.tan(math.radians(hfov_deg) / 2.0)
    return np.array([[f, 0.0, width / 2.0], [0.0, f, height / 2.0], [0.0, 0.0, 1.0]])


def invert(t: np.ndarray) -> np.ndarray:
    """Inverse of a rigid (4, 4) transform."""
    out = np.eye(4)
    out[:3, :3] = t[:3, :3].T
    out[:3, 3] = -t[:3, :3].T @ t[:3, 3]
    return out


def pixel_rays(k: np.ndarray, width: int, height: int) -> np.ndarray:
    """(height, width, 3) float64 unit ray directions through pixel centres, camera (optical) frame."""
    u, v = np.meshgrid(np.arange(width) + 0.5, np.arange(height) + 0.5)
    d = np.stack([(u - k[0, 2]) / k[0, 0], (v - k[1, 2]) / k[1, 1], np.ones_like(u)], -1)
    return d / np.linalg.norm(d, axis=-1, keepdims=True)
