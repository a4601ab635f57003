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

from generator.geometry.transforms import invert
from generator.atomic import write_text
from generator.errors import UserError

CALIB_KEYS = ("P0", "P1", "P2", "P3", "Tr")


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
    """Read a KITTI ``calib.txt``.

    Returns
    -------
    dict of str to ndarray
        Each key's numbers as a (3, 4) float64 matrix when it has 12 values (P0..P3, Tr,
        Tr_velo_to_cam...), (3, 3) for 9 (R0_rect), else flat.

    Raises
    ------
    UserError
        Missing file, a line without ``KEY:``, or non-numeric values (naming file and line).
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as e:
        raise UserError(f"{p}: cannot read calibration: {e}") from None
    out: dict[str, np.ndarray] = {}
    for n, line in enumerate(text.splitlines(), 1):
        if not line.strip():
            continue
        key, sep, rest = line.partition(":")
        if not sep:
            raise UserError(f"{p}: line {n}: expected 'KEY: numbers', got {line[:40]!r}")
        try:
            vals = np.array([float(v) for v in rest.split()], np.float64)
        except ValueError:
            raise UserError(f"{p}: line {n}: {key.strip()}: values must be numbers") from None
        out[key.strip()] = vals.reshape(3, 4) if vals.size == 12 else (vals.reshape(3, 3) if vals.size == 9 else vals)
    return out


def tr_matrix(calib: dict[str, np.ndarray], source: str = "calib.txt") -> np.ndarray:
    """(4, 4) ``Tr`` (velodyne -> cam0) from a parsed calib (``Tr`` or ``Tr_velo_to_cam``)."""
    for key in ("Tr", "Tr_velo_to_cam"):
        if key in calib and np.size(calib[key]) == 12:
            return homogeneous(calib[key])
    raise UserError(f"{source}: no 'Tr' (velodyne to camera) entry with 12 numbers")


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
