"""LiDAR scene flow: a side file per scan, aligned row by row with the ``.bin``.

``sequences/NN/scene_flow/NNNNNN.bin``: float32 little-endian, four values per point, in the
order of the scan's rows (:mod:`generator.motion.scene_flow` defines them):

=====  =======================================================================================
col    content
=====  =======================================================================================
0-2    ``object`` flow: the displacement of the point's surface from its firing instant ``t_p``
       to ``t_p + dt`` (the same column of the next sweep, ``dt`` = 0.1 s), metres, in the LiDAR
       frame the point's ``x, y, z`` are in; exactly 0 on the static town
3      flag: 0 seen (sweep j + 1 has no nearer return in its direction), 1 hidden (something
       nearer stands in front at j + 1), 2 gone (out of the sensor's range or field of view)
=====  =======================================================================================

The flow *with* the ego's motion (``x + ego`` is where sweep ``j + 1``'s raw coordinates put the
surface; the static town moves by the ego's motion alone) is ``E_p (x + object) - x`` with
``E_p = inv(T_world_lidar(t_p + dt)) T_world_lidar(t_p)``: :func:`ego_flow` computes it from the
LiDAR poses ``lidar_meta.json`` records for sweeps ``j`` and ``j + 1`` (``sweep_poses_world``)
and the firing times (``point_times/``). The last sweep of a sequence has no file (no next sweep).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from generator import safeload
from generator.atomic import write_bytes
from generator.errors import UserError

FOLDER = "scene_flow"
VALUES = 4
#: What ``lidar_meta.json`` says about the side files (``scene_flow``).
DESCRIPTION = {
    "files": "scene_flow/NNNNNN.bin (every sweep but the last)",
    "layout": "float32 little-endian, 4 per point in the .bin's row order: object flow x, y, z (metres, the "
              "point's own LiDAR frame), flag (0 seen, 1 hidden, 2 gone at the next sweep)",
    "object_flow": "displacement of the point's surface from its firing instant t_p to t_p + dt (the same column of "
                   "the next sweep); 0 on the static town",
    "ego_flow": "E_p (x + object) - x, E_p = inv(T_world_lidar(t_p + dt)) T_world_lidar(t_p) (sweep_poses_world); "
                "x + ego_flow is where the next sweep's raw coordinates put the surface",
}


def write_scene_flow(seq_dir: str | Path, stem: str, obj: np.ndarray, flag: np.ndarray) -> None:
    """Write scan ``stem``'s scene flow: ``obj`` (n, 3) metres and ``flag`` (n,) 0/1/2 (atomically)."""
    if len(obj) != len(flag):
        raise ValueError(f"{len(obj)} flows but {len(flag)} flags")
    rows = np.empty((len(obj), VALUES), "<f4")
    rows[:, :3] = obj
    rows[:, 3] = flag
    write_bytes(Path(seq_dir) / FOLDER / f"{stem}.bin", rows.tobytes())


def read_scene_flow(seq_dir: str | Path, index: int, n_points: int) -> tuple[np.ndarray, np.ndarray] | None:
    """``((n, 3) float32 object flow, (n,) uint8 flag)`` of scan ``index``, or None without a file.

    Raises
    ------
    UserError
        Unreadable, a length that disagrees with the scan's ``n_points``, non-finite values or
        flags other than 0, 1, 2; one line.
    """
    path = Path(seq_dir) / FOLDER / f"{index:06d}.bin"
    if not os.path.lexists(path):
        return None
    rows = safeload.read_array(path, "<f4", VALUES * 4, finite=True)
    if len(rows) != n_points:
        raise UserError(f"{path}: {len(rows)} rows but the scan has {n_points} points")
    flag = rows[:, 3]
    if len(flag) and not np.isin(flag, (0.0, 1.0, 2.0)).all():
        raise UserError(f"{path}: column 3 (the flag) must be 0, 1 or 2")
    return np.ascontiguousarray(rows[:, :3]), flag.astype(np.uint8)


def poses_at(times: np.ndarray, sample_times: np.ndarray, T_samples: np.ndarray) -> np.ndarray:
    """(k, 4, 4) poses at ``times`` from poses at increasing ``sample_times`` (translation linear,
    rotation by slerp: exact for urbangen's drives, whose poses are linear between these knots)."""
    ts = np.asarray(sample_times, np.float64)
    T = np.asarray(T_samples, np.float64)
    t = np.clip(np.asarray(times, np.float64), ts[0], ts[-1])
    out = np.repeat(np.eye(4)[None], len(t), 0)
    if len(ts) == 1:
        out[:] = T[0]
        return out
    out[:, :3, :3] = Slerp(ts, Rotation.from_matrix(T[:, :3, :3]))(t).as_matrix()
    out[:, :3, 3] = np.stack([np.interp(t, ts, T[:, i, 3]) for i in range(3)], -1)
    return out


def ego_flow(xyz: np.ndarray, obj: np.ndarray, times: np.ndarray | None, record_j: dict,
             record_next: dict) -> np.ndarray:
    """(n, 3) float32 flow with the ego's motion from the object flow (see the module docstring).

    Parameters
    ----------
    xyz, obj : (n, 3) float
        Points and their object flow, metres.
    times : (n,) float or None
        Firing offsets after the sweep start, seconds (``point_times/``; None: all 0).
    record_j, record_next : dict
        ``{"t_s": (k,), "T_world_lidar": (k, 4, 4)}`` of sweeps j and j + 1
        (``lidar_meta.json`` ``sweep_poses_world.frames``); ``t_s`` are offsets after each sweep's
        start, so the point's instant in sweep j + 1 is its own offset ``tau`` there.
    """
    x = np.asarray(xyz, np.float64)
    tau = np.zeros(len(x)) if times is None else np.asarray(times, np.float64)
    tu, back = np.unique(tau, return_inverse=True)
    Tp = poses_at(tu, record_j["t_s"], record_j["T_world_lidar"])
    Tq = poses_at(tu, record_next["t_s"], record_next["T_world_lidar"])
    E = np.linalg.inv(Tq) @ Tp
    q = x + np.asarray(obj, np.float64)
    moved = np.einsum("nij,nj->ni", E[back, :3, :3], q) + E[back, :3, 3]
    return (moved - x).astype(np.float32)
