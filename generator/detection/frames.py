"""Box geometry in any frame: an upright world box seen from a sensor, ego or camera frame.

A box is stored in the world frame (centre, size = length/width/height, yaw of the length axis
about +z). In another frame ``F`` (``T_F_world``, a (4, 4) rigid transform mapping world points
into ``F``) it is a centre and a rotation matrix whose columns are the box's length, width and
height axes written in ``F``. ``yaw_in`` gives the heading about ``F``'s z axis (LiDAR, ego,
world: z up); ``kitti_rotation_y`` the KITTI camera convention (rotation about the camera's y axis,
0 when the length axis points along camera x, right).
"""

from __future__ import annotations

import numpy as np

#: Corner signs of a box, KITTI order: the bottom face (z -) then the top face, each counter-clockwise
#: seen from above starting at front-left (+x, +y).
CORNER_SIGNS = np.array([[1, 1, -1], [1, -1, -1], [-1, -1, -1], [-1, 1, -1],
                         [1, 1, 1], [1, -1, 1], [-1, -1, 1], [-1, 1, 1]], np.float64)


def rot_z(yaw: float) -> np.ndarray:
    """(3, 3) float64 rotation by ``yaw`` radians about +z."""
    c, s = np.cos(yaw), np.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def box_in_frame(center, yaw: float, T_dst_world: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """An upright world box in frame ``dst``.

    Parameters
    ----------
    center : (3,) float
        World frame, metres.
    yaw : float
        Heading of the length axis about world +z, radians.
    T_dst_world : (4, 4) float64

    Returns
    -------
    center : (3,) float64
        In ``dst``, metres.
    rotation : (3, 3) float64
        Columns: the box's length, width and height axes in ``dst``.
    """
    T = np.asarray(T_dst_world, np.float64)
    return T[:3, :3] @ np.asarray(center, np.float64) + T[:3, 3], T[:3, :3] @ rot_z(yaw)


def yaw_in(rotation: np.ndarray) -> float:
    """Heading of the length axis about the frame's +z axis, radians in (-pi, pi]."""
    return float(np.arctan2(rotation[1, 0], rotation[0, 0]))


def kitti_rotation_y(rotation: np.ndarray) -> float:
    """KITTI ``rotation_y`` of a box whose axes are ``rotation`` in a camera (optical) frame, in [-pi, pi]."""
    return float(np.arctan2(-rotation[2, 0], rotation[0, 0]))


def corners(center, size, rotation: np.ndarray) -> np.ndarray:
    """(8, 3) float64 corners (:data:`CORNER_SIGNS` order) of a box in the frame of ``center``/``rotation``."""
    half = CORNER_SIGNS * (np.asarray(size, np.float64) / 2)
    return half @ np.asarray(rotation, np.float64).T + np.asarray(center, np.float64)


def points_in_box(points: np.ndarray, center, size, rotation: np.ndarray, margin: float = 0.0) -> np.ndarray:
    """(n,) bool: which (n, 3) points (same frame as the box) lie inside it grown by ``margin`` metres."""
    local = (np.asarray(points, np.float64) - np.asarray(center, np.float64)) @ np.asarray(rotation, np.float64)
    return np.all(np.abs(local) <= np.asarray(size, np.float64) / 2 + margin, axis=1)
