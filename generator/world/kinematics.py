"""Motion between two instants of the world: actors' rigid displacements, the ego's and a camera's velocity.

Everything the motion ground truth needs from the world in time (optical flow, disparity,
LiDAR scene flow: :mod:`generator.motion`) and what an image's metadata says about motion.
Pure numpy.

A surface point ``X`` (world frame, metres) of actor ``a`` at ``t0`` is at
``T_world_actor(t1) @ inv(T_world_actor(t0)) @ X`` at ``t1`` (actors are rigid bodies, but for a
walker's limbs, whose gait phase meshes the :class:`Mover` carries); a point of the static town stays
where it is. Velocities are central differences over ``+-h`` seconds (by
default the ego track's sample spacing), the same numbers :meth:`generator.world.actors.Track.velocity`
gives for actors.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from generator.geometry.transforms import invert

#: Step of the central differences when the ego has no sampled track (a constant-speed route), seconds.
DEFAULT_H_S = 0.05


@dataclass(frozen=True)
class Mover:
    """One actor between two instants.

    Attributes
    ----------
    instance_id : int
        The actor's instance id (what the instance pass and the LiDAR labels hold).
    T0, T1 : (4, 4) float64
        ``T_world_actor`` at the two instants.
    box_center, box_size : (3,) float64
        The actor's box in its local frame (centre; length, width, height), metres (a walker's: the box
        of every gait phase, so it holds the mesh shown at either instant).
    meshes : (Mesh, Mesh) or None
        A walker whose gait phase differs between the instants: the phase meshes shown at ``t0`` and
        ``t1`` (same faces), so a surface point's own limb motion can be added to :attr:`M`
        (:func:`generator.motion.articulation.carry`); None for a rigid actor.
    """

    instance_id: int
    T0: np.ndarray
    T1: np.ndarray
    box_center: np.ndarray
    box_size: np.ndarray
    meshes: tuple | None = None

    @property
    def M(self) -> np.ndarray:
        """(4, 4) float64 world-frame displacement: ``X(t1) = M @ X(t0)``."""
        return self.T1 @ invert(self.T0)

    def local(self, points_world: np.ndarray) -> np.ndarray:
        """(n, 3) float64: world points at ``t0`` in the actor's box frame (origin at the box centre)."""
        p = np.asarray(points_world, np.float64).reshape(-1, 3) - self.T0[:3, 3]
        return p @ self.T0[:3, :3] - self.box_center

    def inside(self, points_world: np.ndarray, margin: float) -> np.ndarray:
        """(n,) bool: which world points at ``t0`` lie in the box grown by ``margin`` metres."""
        return np.all(np.abs(self.local(points_world)) <= self.box_size / 2 + margin, axis=1)


def movers(world, t0: float, t1: float) -> list[Mover]:
    """Every actor of ``world`` between ``t0`` and ``t1`` seconds (empty for a frozen town or None)."""
    if world is None or not world.actors:
        return []
    A0, A1 = world.T_world_actor(t0), world.T_world_actor(t1)
    return [Mover(a.instance_id, A0[i], A1[i], np.asarray(a.box_center, np.float64), np.asarray(a.size, np.float64),
                  _phase_meshes(world, a, t0, t1))
            for i, a in enumerate(world.actors)]


def _phase_meshes(world, actor, t0: float, t1: float) -> tuple | None:
    """(mesh at t0, mesh at t1) of a walker whose gait phase changes between the instants, else None."""
    if actor.gait is None:
        return None
    k0, k1 = actor.prototype_at(t0), actor.prototype_at(t1)
    return None if k0 == k1 else (world.prototypes[k0], world.prototypes[k1])


def _step(ego, h: float | None) -> float:
    if h is not None:
        return float(h)
    track = getattr(ego, "track", None)
    return float(track.dt) if track is not None else DEFAULT_H_S


def _yaw(R: np.ndarray) -> np.ndarray:
    return np.arctan2(R[..., 1, 0], R[..., 0, 0])


def rotation_vector(R: np.ndarray) -> np.ndarray:
    """(3,) float64 axis * angle (radians) of a rotation matrix (angles below pi)."""
    c = np.clip((np.trace(R) - 1.0) / 2.0, -1.0, 1.0)
    angle = float(np.arccos(c))
    w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    s = np.sin(angle)
    return w * (0.5 if angle < 1e-9 else angle / (2.0 * s))


def ego_motion(ego, t: float, h: float | None = None) -> dict:
    """The ego's motion at ``t``: velocity (world and ego axes), speed and yaw rate.

    Parameters
    ----------
    ego : object
        The world's ego trajectory (``T_world_ego(t) -> (k, 4, 4)``).
    t : float
        Seconds.
    h : float, optional
        Half-step of the central difference (default: the ego track's sample spacing).

    Returns
    -------
    dict
        ``velocity_mps`` (3,) world frame; ``velocity_ego_mps`` (3,) ego axes (x forward, y left,
        z up); ``speed_mps`` (horizontal); ``yaw_rate_rad_s`` (counter-clockwise seen from above).
    """
    h = _step(ego, h)
    T = ego.T_world_ego(np.array([t - h, t + h], np.float64))
    Tc = ego.T_world_ego(np.array([t], np.float64))[0]
    v = (T[1, :3, 3] - T[0, :3, 3]) / (2 * h)
    dyaw = float(np.angle(np.exp(1j * (_yaw(T[1, :3, :3]) - _yaw(T[0, :3, :3])))))
    return {"velocity_mps": v.tolist(), "velocity_ego_mps": (Tc[:3, :3].T @ v).tolist(),
            "speed_mps": float(np.hypot(v[0], v[1])), "yaw_rate_rad_s": dyaw / (2 * h)}


def camera_motion(ego, T_ego_camera: np.ndarray, t: float, h: float | None = None) -> dict:
    """A camera's twist at ``t`` (riding the ego at ``T_ego_camera``), in its own optical axes.

    Returns
    -------
    dict
        ``velocity_mps`` (3,): the camera centre's velocity in the camera frame at ``t`` (x right,
        y down, z forward), m/s; ``angular_velocity_rad_s`` (3,): its angular velocity in the same
        axes. With the depth of a static point these give its optical flow; the rest of a
        pixel's flow is its object's own motion.
    """
    h = _step(ego, h)
    T = ego.T_world_ego(np.array([t - h, t, t + h], np.float64)) @ T_ego_camera
    R = T[1, :3, :3]
    v = R.T @ (T[2, :3, 3] - T[0, :3, 3]) / (2 * h)
    w = rotation_vector(T[0, :3, :3].T @ T[2, :3, :3]) / (2 * h)  # body-frame rotation over 2h
    return {"velocity_mps": v.tolist(), "angular_velocity_rad_s": w.tolist()}
