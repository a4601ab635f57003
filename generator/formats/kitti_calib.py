"""KITTI odometry ``calib.txt`` and ``poses.txt`` conventions, from the urbangen rig.

``calib.txt`` (one ``KEY: 12 numbers`` line each, row-major 3x4):

* ``P0`` .. ``P3``: projection matrices of the rectified KITTI stereo pair the sequence's
  ``image_2/`` (left) and ``image_3/`` (right) come from (:meth:`generator.world.rig.Rig.stereo_projections`):
  ``P2 = K [I | 0]``, ``P3 = K [I | (-b, 0, 0)]`` with the stereo baseline ``b`` (0.54 m by
  default, as KITTI's). urbangen renders no grayscale pair, so ``P0 = P2`` and ``P1 = P3``.
  ``K`` from the spec's hfov and the render config's resolution. Pixel convention of the
  rig: the origin is the top-left CORNER of the top-left pixel, so ``floor(u), floor(v)`` is
  the pixel hit; for OpenCV's integer-centre convention subtract 0.5 from ``cx, cy``.
* ``Tr``: velodyne -> cam0 (= cam2, ``T_cam0_velo``), from the rig mounts: the stereo pair is
  fixed (no jitter), so ``P2 @ Tr`` projects every scan into its ``image_2`` frame
  (:meth:`generator.world.rig.Rig.T_camera_lidar`). The seed-003 images in ``images/``
  carry a random jitter each; their exact transform is in their metadata.
  With the default KITTI-like mounts it is about ``R = [[0,-1,0],[0,0,-1],[1,0,0]]``,
  ``t = (0, -0.08, -0.27)`` m, like KITTI's own.

``poses.txt``: line ``i`` is the pose of cam0 at scan ``i`` in the cam0 frame of scan 0
(``T_cam0(0)_cam0(i)``), 3x4 row-major, as in KITTI odometry. The LiDAR pose in the first
LiDAR frame is then ``inv(Tr) @ pose_i @ Tr`` (what the SemanticKITTI API computes);
urbangen files each scan under the LiDAR pose at its sweep start.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from generator import safeload
from generator.atomic import write_text
from generator.errors import SpecError, UserError
from generator.geometry.transforms import invert

CALIB_KEYS = ("P0", "P1", "P2", "P3", "Tr")
#: Tolerance of :func:`rigid_problem` on ``R R^T - I`` and ``det R - 1``.
RIGID_TOL = 1e-3


def homogeneous(m: np.ndarray) -> np.ndarray:
    """(4, 4) float64 from a (3, 4) matrix (bottom row 0 0 0 1)."""
    out = np.eye(4)
    out[:3] = np.asarray(m, np.float64).reshape(3, 4)
    return out


def kitti_calib(rig, width: int, height: int) -> dict[str, np.ndarray]:
    """``P0``..``P3`` and ``Tr`` as (3, 4) float64 for a render of ``width`` x ``height`` pixels.

    Parameters
    ----------
    rig : generator.world.rig.Rig
        Camera intrinsics and the nominal (jitter-free) camera and LiDAR mounts.
    """
    out = rig.stereo_projections(width, height)
    out["Tr"] = rig.T_camera_lidar()[:3]
    return out


def format_calib(calib: dict[str, np.ndarray]) -> str:
    """``KEY: v v v ...`` lines (``%.12e``, KITTI's own precision)."""
    lines = []
    for key, m in calib.items():
        vals = np.asarray(m, np.float64).reshape(-1)
        lines.append(f"{key}: " + " ".join(f"{v:.12e}" for v in vals))
    return "\n".join(lines) + "\n"


def write_calib(path: str | Path, calib: dict[str, np.ndarray]) -> None:
    """Write ``calib.txt`` atomically."""
    write_text(path, format_calib(calib))


def read_calib(path: str | Path) -> dict[str, np.ndarray]:
    """Read a KITTI ``calib.txt`` (through :mod:`generator.safeload`: a regular UTF-8 file within the
    table size limit).

    Returns
    -------
    dict of str to ndarray
        Each key's numbers as a (3, 4) float64 matrix when it has 12 values (P0..P3, Tr,
        Tr_velo_to_cam...), (3, 3) for 9 (R0_rect), else flat.

    Raises
    ------
    UserError
        Missing or special file, a line without ``KEY:``, a key twice, non-numeric or
        non-finite values, or a ``P0``..``P3``/``Tr`` entry without 12 numbers (naming file
        and line, never quoting it).
    """
    src = str(path)
    text = safeload.read_text(path, source=src, max_bytes=safeload.MAX_TABLE_BYTES)
    out: dict[str, np.ndarray] = {}
    for n, line in enumerate(text.splitlines(), 1):
        if not line.strip():
            continue
        key, sep, rest = line.partition(":")
        key = key.strip()
        if not sep or not key or len(key) > 32 or not key.replace("_", "").isalnum() or not key.isascii():
            raise SpecError(src, f"line {n}", "expected 'KEY: numbers' (a short name, a colon, then numbers)")
        if key in out:
            raise SpecError(src, f"line {n}", f"{key}: given twice")
        try:
            vals = np.array([float(v) for v in rest.split()], np.float64)
        except ValueError:
            raise SpecError(src, f"line {n}", f"{key}: values must be numbers") from None
        if not np.isfinite(vals).all():
            raise SpecError(src, f"line {n}", f"{key}: values must be finite numbers")
        if key in CALIB_KEYS + ("Tr_velo_to_cam",) and vals.size != 12:
            raise SpecError(src, f"line {n}", f"{key}: expected 12 numbers (a 3x4 matrix), got {vals.size}")
        out[key] = vals.reshape(3, 4) if vals.size == 12 else (vals.reshape(3, 3) if vals.size == 9 else vals)
    return out


def tr_matrix(calib: dict[str, np.ndarray], source: str = "calib.txt") -> np.ndarray:
    """(4, 4) ``Tr`` (velodyne -> cam0) from a parsed calib (``Tr`` or ``Tr_velo_to_cam``).

    Raises
    ------
    UserError
        No such entry, or its rotation part is not a rotation (the transform must be rigid).
    """
    for key in ("Tr", "Tr_velo_to_cam"):
        if key in calib and np.size(calib[key]) == 12:
            tr = homogeneous(calib[key])
            problem = rigid_problem(tr)
            if problem:
                raise UserError(f"{source}: {key}: {problem}")
            return tr
    raise UserError(f"{source}: no 'Tr' (velodyne to camera) entry with 12 numbers")


def rigid_problem(T: np.ndarray, tol: float = RIGID_TOL) -> str | None:
    """Why a (4, 4) or (3, 4) transform is not rigid (rotation part not orthonormal with det +1), or None.

    ``tol`` bounds ``|R R^T - I|`` elementwise and ``|det R - 1|``: loose enough for poses
    printed with a few digits, tight enough to catch a scale, a shear or garbage.
    """
    r = np.asarray(T, np.float64)[:3, :3]
    if not np.isfinite(r).all():
        return "is not finite"
    if np.abs(r).max() > 1 + tol or np.abs(r @ r.T - np.eye(3)).max() > tol or abs(np.linalg.det(r) - 1.0) > tol:
        return "rotation part is not a rotation (not orthonormal with determinant +1)"
    return None


def camera_poses(T_world_velo: np.ndarray, tr: np.ndarray) -> np.ndarray:
    """KITTI ``poses.txt`` content from LiDAR world poses.

    Parameters
    ----------
    T_world_velo : (n, 4, 4) float64
        LiDAR pose (sweep start) of each scan, world frame.
    tr : (4, 4) float64
        ``T_cam0_velo``.

    Returns
    -------
    (n, 4, 4) float64
        ``T_cam0(0)_cam0(i)``.
    """
    t_world_cam = np.asarray(T_world_velo, np.float64) @ invert(tr)
    return invert(t_world_cam[0]) @ t_world_cam


def lidar_poses(cam_poses: np.ndarray, tr: np.ndarray) -> np.ndarray:
    """(n, 4, 4) LiDAR poses in the first LiDAR frame: ``inv(Tr) @ pose @ Tr`` (SemanticKITTI API)."""
    return invert(tr) @ np.asarray(cam_poses, np.float64) @ tr
