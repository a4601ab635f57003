"""LiDAR points -> camera pixels (seed 001 Eq. 1), motion de-skew, occlusion test, mask boundaries.

Eq. 1 of seed 001: ``d [u, v, 1]^T = K T [X, Y, Z, 1]^T`` with ``T`` the camera-from-LiDAR
transform and ``d`` the depth along the optical axis. The rig's pixel convention
(:mod:`generator.world.rig`) puts the origin at the top-left CORNER of the top-left pixel, so a
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
:func:`deskew` moves every point into the sensor frame at the sweep start with the sensor
poses recorded during the sweep (:meth:`generator.world.rig.Rig.sweep_record`; exact for urbangen's
routes). Seed 001 projected raw KITTI scans: on the default town at 8 m/s that leaves up to
0.8 m of skew and lowers the agreement (``bench/fusion_skew.py``).

Occlusion
---------
Seed 001 had no occlusion test: a LiDAR point hidden from the camera (behind a car, seen
from the LiDAR 0.3 m higher and behind) took the label of whatever covers its pixel. Here a
point is visible when its distance from the camera centre agrees with the rendered depth of
its pixel (distance along the pixel-centre ray to the real geometry) within

``|distance - depth| <= tol = max(abs_m, rel * distance)``

* ``abs_m`` (default 0.1 m): float32 geometry and range (~1e-5 m), de-skew residual on
  curves (millimetres), and the +-0.05 m per-axis jitter of the domain-gap preset (at most
  0.087 m); a 0.1 m gap is still far thinner than any occluder in the town (a pole is 0.12 m).
* ``rel`` (default 1 %): errors that grow with distance -- Blender's and Embree's float32
  rays differ by up to ~2e-4 of the range on grazing rays (``tests/test_fusion.py``
  measures it), and the LiDAR rain model's range noise (sigma up to 2 % of the range in
  heavy rain) scales with range.
* sub-pixel position: the depth is sampled at the pixel centre but the point lies anywhere
  in its pixel; on a slanted surface (the road ahead at a grazing angle changes depth by
  metres per pixel at low resolution) the two differ far beyond the tolerance. The test
  therefore also accepts the depth of the pixel centre's surface extrapolated to the point's
  sub-pixel position (linear in inverse depth towards the neighbour pixel on the point's
  side, exact for planes; see :func:`candidate_distances`).

The tolerance is two-sided: a point much NEARER than the rendered surface is also rejected
(the camera sees something else there: e.g. a point on an object's edge whose pixel centre
sees the background).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from generator.world import rig

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


def deskew(xyz: np.ndarray, times: np.ndarray, sample_times: np.ndarray, T_world_samples: np.ndarray) -> np.ndarray:
    """Move skewed points into the sensor frame at the sweep start.

    Parameters
    ----------
    xyz : (n, 3) float
        Sensor frame at each point's firing instant, metres.
    times : (n,) float
        Firing offset after the sweep start, seconds (0 = no skew).
    sample_times : (k,) float
        Increasing offsets of the known sensor poses, seconds; the first is 0 (sweep start).
    T_world_samples : (k, 4, 4) float64
        Sensor poses at ``sample_times`` (``lidar_meta.json`` ``sweep_poses_world``, see
        :meth:`generator.world.rig.Rig.sweep_record`). Between samples the pose is interpolated
        (translation linear, rotation by slerp), exact for urbangen's piecewise-linear routes.

    Returns
    -------
    (n, 3) float64
        Sensor frame at the sweep start (``T_world_samples[0]``), metres.
    """
    ts = np.asarray(sample_times, np.float64)
    poses = np.asarray(T_world_samples, np.float64)
    rel = rig.invert(poses[0]) @ poses  # (k, 4, 4) sample poses in the start frame
    # points share their column's firing time: interpolate once per distinct time
    t, inv = np.unique(np.clip(np.asarray(times, np.float64), ts[0], ts[-1]), return_inverse=True)
    rot = Slerp(ts, Rotation.from_matrix(rel[:, :3, :3]))(t).as_matrix()
    trans = np.stack([np.interp(t, ts, rel[:, i, 3]) for i in range(3)], -1)
    return np.einsum("nij,nj->ni", rot[inv], np.asarray(xyz, np.float64)) + trans[inv]


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


def inverse_depth(depth: np.ndarray, K: np.ndarray) -> np.ndarray:
    """(H, W) float64 inverse optical depth ``1 / z`` of each pixel centre (0 for sky).

    On a planar surface ``1 / z`` is an affine function of the pixel coordinates, which
    is what makes the sub-pixel prediction of :func:`candidate_distances` exact for planes.

    Parameters
    ----------
    depth : (H, W) float
        Distance along each pixel-centre ray, metres; inf = sky.
    K : (3, 3) float
        Intrinsics.
    """
    h, w = depth.shape
    z = np.asarray(depth, np.float64) * rig.pixel_rays(np.asarray(K, np.float64), w, h)[..., 2]
    with np.errstate(divide="ignore"):
        return np.where(np.isfinite(z) & (z > 0), 1.0 / z, 0.0)


def candidate_distances(proj: Projection, depth: np.ndarray, K: np.ndarray,
                        inv_z: np.ndarray | None = None) -> np.ndarray:
    """(m, 4) float64 rendered distances the point may have to match, metres (inf = none).

    Column 0 is the pixel-centre depth. Columns 1-3 extrapolate the surface of the pixel
    centre to the point's sub-pixel position, linearly in inverse depth towards the
    neighbour on the point's side along u, along v, and along both; exact on any plane. A
    neighbour across a depth edge gives a wrong plane, but with the point at most half a
    pixel from the centre such a prediction stays at least halfway (in inverse depth)
    between the two surfaces, so a hidden point behind an edge still fails the test.
    """
    h, w = depth.shape
    inv = inverse_depth(depth, K) if inv_z is None else inv_z
    r, c = proj.row, proj.col
    du, dv = proj.u - (c + 0.5), proj.v - (r + 0.5)
    cu = np.clip(c + np.where(du >= 0, 1, -1), 0, w - 1)
    rv = np.clip(r + np.where(dv >= 0, 1, -1), 0, h - 1)
    w0 = inv[r, c]
    step_u = (inv[r, cu] - w0) * np.abs(du)
    step_v = (inv[rv, c] - w0) * np.abs(dv)
    inv_pred = np.stack([w0, w0 + step_u, w0 + step_v, w0 + step_u + step_v], -1)
    with np.errstate(divide="ignore"):
        z_pred = np.where(inv_pred > 0, 1.0 / inv_pred, np.inf)
    out = z_pred * (proj.distance / proj.z)[:, None]  # optical depth -> distance along the point's ray
    out[:, 0] = np.asarray(depth, np.float64)[r, c]  # the centre value itself, exactly as rendered
    out[w0 <= 0] = np.inf
    return out


def visible(proj: Projection, depth: np.ndarray, K: np.ndarray, abs_m: float = ABS_TOL_M, rel: float = REL_TOL,
            subpixel: bool = True, inv_z: np.ndarray | None = None) -> np.ndarray:
    """(m,) bool: the occlusion test -- the point's distance matches its pixel's rendered depth.

    Parameters
    ----------
    proj : Projection
    depth : (H, W) float32
        Distance along each pixel-centre ray to the real geometry, metres; inf = sky.
    K : (3, 3) float
        Intrinsics of the image.
    abs_m, rel : float
        Tolerance ``max(abs_m, rel * distance)``, metres.
    subpixel : bool
        Also accept the sub-pixel predictions of :func:`candidate_distances` (else only the
        pixel-centre depth).
    inv_z : (H, W) float64, optional
        :func:`inverse_depth` of the image, when already computed.
    """
    cand = candidate_distances(proj, depth, K, inv_z)
    if not subpixel:
        cand = cand[:, :1]
    tol = np.maximum(abs_m, rel * proj.distance)
    return np.any(np.abs(cand - proj.distance[:, None]) <= tol[:, None], axis=1)


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
