"""Moving actors in fusion: de-skew by the actor's own motion, and keep movers out of the map.

A point fired at ``t_p`` on actor ``a`` is where the actor's surface was at ``t_p``. The
sensor de-skew (:func:`generator.fusion.projection.deskew`) fixes the sensor's motion only;
to draw the point where that surface is when the image is exposed (``t_img``) it is moved
with the actor:

``X_world(t_img) = T_world_actor(t_img) @ inv(T_world_actor(t_p)) @ X_world(t_p)``

Static points keep the sensor de-skew alone. Which points belong to which actor comes from
the instance id (the high 16 bits of the ``.label`` files, :attr:`Actor.instance_id`, stable
for the whole sequence).

Where the actor poses come from: the world is rebuilt from the spec
(:func:`generator.jobs.boxes.sequence_world`, deterministic from the seed), so poses at any
firing instant are the tracks themselves -- exact, not an interpolation of rounded poses
written per sweep. Callers hand :func:`actor_poses` of that world (or any mapping of
instance id to a pose function) to :func:`deskew_movers`.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping

import numpy as np

from generator.world import rig

log = logging.getLogger(__name__)

#: SemanticKITTI raw ids of moving classes (moving-car 252 ... moving-other-vehicle 259).
MOVING_RAW = (252, 259)

PoseFn = Callable[[np.ndarray], np.ndarray]


def _invert_rigid(T: np.ndarray) -> np.ndarray:
    """(k, 4, 4) inverses of (k, 4, 4) rigid transforms."""
    out = np.repeat(np.eye(4)[None], len(T), 0)
    R = np.transpose(T[:, :3, :3], (0, 2, 1))
    out[:, :3, :3] = R
    out[:, :3, 3] = -np.einsum("kij,kj->ki", R, T[:, :3, 3])
    return out


def actor_poses(world) -> dict[int, PoseFn]:
    """Instance id -> ``T_world_actor(t)`` ((k,) seconds -> (k, 4, 4)) of every actor of ``world``."""
    return {a.instance_id: a.track.pose for a in (world.actors if world is not None else ())}


def is_moving_label(semantic: np.ndarray) -> np.ndarray:
    """(n,) bool: SemanticKITTI raw ids 252-259 (the low 16 bits of a label)."""
    s = np.asarray(semantic).astype(np.int64) & 0xFFFF
    return (s >= MOVING_RAW[0]) & (s <= MOVING_RAW[1])


def static_mask(semantic: np.ndarray, instance: np.ndarray, actor_instances=()) -> np.ndarray:
    """(n,) bool: points of the static world -- not labelled moving-* and not on any actor.

    An actor standing still (a car at a red light) keeps its static raw id but is still a
    mover: its points are dropped through ``actor_instances`` (instance ids of the actors).
    """
    keep = ~is_moving_label(semantic)
    ids = np.fromiter((int(i) for i in actor_instances), np.int64)
    if ids.size:
        keep &= ~np.isin(np.asarray(instance, np.int64), ids)
    return keep


def deskew_movers(xyz_start: np.ndarray, instance: np.ndarray, times: np.ndarray | None, t_sweep: float,
                  t_target: float, T_world_lidar_start: np.ndarray, poses: Mapping[int, PoseFn]) -> np.ndarray:
    """Move actor points to where their actor is at ``t_target``.

    Parameters
    ----------
    xyz_start : (n, 3) float
        Points after the sensor de-skew: LiDAR frame at the sweep start, metres.
    instance : (n,) integer
        Instance id per point.
    times : (n,) float or None
        Firing offset after the sweep start, seconds (None: every point at the sweep start).
    t_sweep : float
        Sweep start, seconds on the world timeline.
    t_target : float
        Instant the points are wanted at (the image exposure), seconds.
    T_world_lidar_start : (4, 4) float64
        LiDAR pose at the sweep start.
    poses : mapping int -> callable
        Instance id -> ``T_world_actor(t)`` (see :func:`actor_poses`).

    Returns
    -------
    (n, 3) float64
        LiDAR frame at the sweep start; actor points moved by their actor's motion from their
        firing instant to ``t_target``, every other point unchanged.
    """
    out = np.array(xyz_start, np.float64, copy=True).reshape(-1, 3)
    inst = np.asarray(instance, np.int64)
    if not poses or not len(out):
        return out
    tp_all = t_sweep + (np.zeros(len(out)) if times is None else np.asarray(times, np.float64))
    T_ws = np.asarray(T_world_lidar_start, np.float64)
    T_sw = rig.invert(T_ws)
    moved = 0
    for iid in np.unique(inst[np.isin(inst, np.fromiter(poses, np.int64))]):
        idx = np.flatnonzero(inst == iid)
        tp, back = np.unique(tp_all[idx], return_inverse=True)  # points share their column's time
        pose = poses[int(iid)]
        M = pose(np.array([t_target], np.float64))[0] @ _invert_rigid(pose(tp))
        M = np.einsum("ij,njk,kl->nil", T_sw, M, T_ws)  # in the sweep-start LiDAR frame
        p = out[idx]
        out[idx] = np.einsum("nij,nj->ni", M[back, :3, :3], p) + M[back, :3, 3]
        moved += len(idx)
    log.debug("de-skewed %d actor points to t = %.3f s", moved, t_target)
    return out
