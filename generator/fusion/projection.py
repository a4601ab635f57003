"""LiDAR points -> camera pixels (seed 001 Eq. 1), motion de-skew, occlusion test, mask boundaries.

Eq. 1 of seed 001: ``d [u, v, 1]^T = K T [X, Y, Z, 1]^T`` with ``T`` the camera-from-LiDAR
transform and ``d`` the depth along the optical axis. The rig's pixel convention
(:mod:`generator.rig`) puts the origin at the top-left CORNER of the top-left pixel, so a
point at ``(u, v)`` falls in pixel ``(row, col) = (floor(v), floor(u))``.

Which transform
---------------
The camera of frame ``k`` carries a random yaw/pitch/roll jitter, so the exact transform is
``T_camera_lidar = inv(T_world_camera_k) @ T_world_lidar_k`` from the image metadata and the
LiDAR mount, not ``calib.txt``'s ``Tr`` (the nominal mount without jitter).

Motion skew
-----------
With motion skew on, each firing column keeps the sensor-frame coordinates of its own
firing instant ``t_k + tau`` while the ego moves; the image is exposed at ``t_k``.
:func:`deskew` moves every point into the sensor frame at the sweep start by interpolating
the sensor pose between the sweep start and end (translation linear, rotation by slerp,
both in the start frame). Unlike seed 001, which projected raw KITTI scans.

Occlusion
---------
Seed 001 had no occlusion test: a LiDAR point hidden from the camera (behind a car, seen
from the LiDAR 0.3 m higher and behind) took the label of whatever covers its pixel. Here a
point is visible when its distance from the camera centre agrees with the rendered depth of
its pixel (distance along the pixel-centre ray to the real geometry) within

``tol = max(abs_m, rel * distance) + |g_u| |u - u_c| + |g_v| |v - v_c|``

* ``abs_m`` (default 0.1 m): float32 geometry and range (~1e-5 m), de-skew residual on
  curves (millimetres), and the +-0.05 m per-axis jitter of the domain-gap preset (at most
  0.087 m); a 0.1 m gap is still far thinner than any occluder in the town (a pole is 0.12 m).
* ``rel`` (default 1 %): errors that grow with distance -- the T_world_camera
  metadata is rounded to 1e-9, image depth is float32, and LiDAR range noise models
  (rain) scale with range.
* the sub-pixel term: the depth is sampled at the pixel centre ``(u_c, v_c)`` but the
  point lies anywhere in the pixel; on a slanted surface (the road ahead at a grazing
  angle changes depth by metres per pixel at low resolution) the depth at the point
  differs by the local depth gradient times the offset. The gradient ``g`` per axis is the
  smaller of the forward and backward differences, so a depth jump on one side of the pixel
  (an occluding edge) does not widen the tolerance.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from generator import rig

#: Default occlusion tolerances (see the module docstring).
ABS_TOL_M = 0.1
REL_TOL = 0.01
NEAR_M = 0.1


def transform(T: np.ndarray, xyz: np.ndarray) -> np.ndarray:
    """(n, 3) float64: points ``xyz`` (n, 3) mapped by the rigid (4, 4) transform ``T``."""
    p = np.asarray(xyz, np.float64)
    return p @ T[:3, :3].T + T[:3, 3]


def camera_from_lidar(T_world_camera: np.ndarray, T_world_lidar: np.ndarray) -> np.ndarray:
    """``T_camera_lidar`` (4, 4) float64 from two world poses (camera in the optical frame)."""
    return rig.invert(np.asarray(T_world_camera, np.float64)) @ np.asarray(T_world_lidar, np.float64)


def deskew(xyz: np.ndarray, times: np.ndarray, T_world_start: np.ndarray, T_world_end: np.ndarray,
           duration: float) -> np.ndarray:
    """Move skewed points into the sensor frame at the sweep start.

    Parameters
    ----------
    xyz : (n, 3) float
        Sensor frame at each point's firing instant, metres.
    times : (n,) float
        Firing offset after the sweep start, seconds (0 = no skew).
    T_world_start, T_world_end : (4, 4) float64
        Sensor poses at the sweep start and at ``duration`` seconds later.
    duration : float
        Seconds between the two poses (one rotation, e.g. 0.1 s at 10 Hz).

    Returns
    -------
    (n, 3) float64
        Sensor frame at the sweep start, metres.
    """
    rel = rig.invert(np.asarray(T_world_start, np.float64)) @ np.asarray(T_world_end, np.float64)
    alpha = np.clip(np.asarray(times, np.float64) / float(duration), 0.0, 1.0)
    slerp = Slerp([0.0, 1.0], Rotation.from_matrix(np.stack([np.eye(3), rel[:3, :3]])))
    rot = slerp(alpha)
    return rot.apply(np.asarray(xyz, np.float64)) + alpha[:, None] * rel[:3, 3]


@dataclass
class Projection:
    """LiDAR points that land inside the image, in front of the camera.

    Attributes
    ----------
    index : (m,) int64
        Rows of the projected point array.
    u, v : (m,) float64
        Pixel coordinates (origin at the top-left corner of the image).
    row, col : (m,) int64
        The pixel hit: ``floor(v)``, ``floor(u)``.
    distance : (m,) float64
        Distance from the camera centre, metres (what the EXR depth holds along its ray).
    z : (m,) float64
        Depth along the optical axis (``d`` of Eq. 1), metres.
    """

    index: np.ndarray
    u: np.ndarray
    v: np.ndarray
    row: np.ndarray
    col: np.ndarray
    distance: np.ndarray
    z: np.ndarray


def project(xyz_camera: np.ndarray, K: np.ndarray, width: int, height: int, near: float = NEAR_M) -> Projection:
    """Seed 001 Eq. 1: ``d [u, v, 1]^T = K X_cam``; keep points in front (``z > near``) and inside.

    Parameters
    ----------
    xyz_camera : (n, 3) float
        Points in the camera optical frame (x right, y down, z forward), metres.
    K : (3, 3) float
        Intrinsics.
    width, height : int
        Image size, pixels.
    near : float
        Points with ``z <= near`` metres are dropped.
    """
    p = np.asarray(xyz_camera, np.float64)
    z = p[:, 2]
    front = np.flatnonzero(z > near)
    q = p[front] @ np.asarray(K, np.float64).T
    u, v = q[:, 0] / q[:, 2], q[:, 1] / q[:, 2]
    inside = (u >= 0) & (u < width) & (v >= 0) & (v < height)
    idx = front[inside]
    u, v = u[inside], v[inside]
    pc = p[idx]
    return Projection(idx, u, v, np.floor(v).astype(np.int64), np.floor(u).astype(np.int64),
                      np.linalg.norm(pc, axis=1), pc[:, 2])


def depth_gradients(depth: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per-pixel depth change per pixel along u and v: the smaller one-sided difference.

    Parameters
    ----------
    depth : (H, W) float
        Metres, inf for sky.

    Returns
    -------
    g_u, g_v : (H, W) float64
        |d depth / d u| and |d depth / d v|, metres per pixel (inf where both neighbours differ
        infinitely, e.g. a one-pixel object against the sky).
    """
    d = np.asarray(depth, np.float64)
    out = []
    for axis in (1, 0):
        diff = np.abs(np.diff(d, axis=axis))
        diff = np.where(np.isnan(diff), np.inf, diff)  # inf - inf (sky next to sky) -> treat as unknown
        pad = [(0, 0), (0, 0)]
        pad[axis] = (1, 0)
        back = np.pad(diff, pad, constant_values=np.inf)
        pad[axis] = (0, 1)
        fwd = np.pad(diff, pad, constant_values=np.inf)
        out.append(np.minimum(back, fwd))
    return out[0], out[1]


def occlusion_tolerance(proj: Projection, depth: np.ndarray, abs_m: float = ABS_TOL_M,
                        rel: float = REL_TOL, gradients: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
    """(m,) float64 tolerance in metres for each projected point (formula in the module docstring)."""
    g_u, g_v = depth_gradients(depth) if gradients is None else gradients
    gu, gv = g_u[proj.row, proj.col], g_v[proj.row, proj.col]
    du, dv = np.abs(proj.u - (proj.col + 0.5)), np.abs(proj.v - (proj.row + 0.5))
    sub = np.where(np.isfinite(gu), gu * du, 0.0) + np.where(np.isfinite(gv), gv * dv, 0.0)
    return np.maximum(abs_m, rel * proj.distance) + sub


def visible(proj: Projection, depth: np.ndarray, abs_m: float = ABS_TOL_M, rel: float = REL_TOL,
            gradients: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
    """(m,) bool: the occlusion test -- the point's distance matches its pixel's rendered depth.

    Parameters
    ----------
    proj : Projection
    depth : (H, W) float32
        Distance along each pixel-centre ray to the real geometry, metres; inf = sky.
    """
    d = np.asarray(depth)[proj.row, proj.col].astype(np.float64)
    tol = occlusion_tolerance(proj, depth, abs_m, rel, gradients)
    return np.isfinite(d) & (np.abs(proj.distance - d) <= tol)


def boundary_mask(class_id: np.ndarray, radius: int = 1) -> np.ndarray:
    """(H, W) bool: pixels with a different class within ``radius`` pixels (8-neighbourhood).

    Parameters
    ----------
    class_id : (H, W) integer
        Label map (the masks).
    """
    c = np.asarray(class_id)
    h, w = c.shape
    pad = np.pad(c, radius, mode="edge")
    out = np.zeros((h, w), bool)
    for dy in range(-radius, radius + 1):
        for dx in range(-radius, radius + 1):
            if dy or dx:
                out |= pad[radius + dy: radius + dy + h, radius + dx: radius + dx + w] != c
    return out
