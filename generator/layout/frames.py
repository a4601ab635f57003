"""The frame plan: where the ego is and how the camera is turned at every dataset frame.

Frame ``k`` sits ``k * paths.spacing_m`` metres along the scene's main route (route 0),
reached at time ``t_k = s_k / paths.speed_mps``. The LiDAR sweep of a frame starts at
``t_k`` and lasts one rotation (0.1 s at 10 Hz) while the ego keeps moving; the camera
image is exposed at ``t_k``. The camera's random yaw / pitch / roll for frame ``k``
comes from the named stream ``("frame", k, "camera")``, so it never depends on how
many frames are planned or which other features draw numbers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from generator import rig
from generator.rng import stream
from generator.scene import SceneModel
from generator.spec.model import SceneSpec


@dataclass(frozen=True)
class Frame:
    """One dataset frame.

    Attributes
    ----------
    index : int
        Frame number (0-based), the ``NNNNNN`` of file names.
    s : float
        Arc length along the route at the frame time, metres.
    t : float
        Seconds since the start of the sequence.
    T_world_ego : (4, 4) float64
        Ego pose at ``t``.
    camera_jitter : (3,) float
        Camera (yaw, pitch, roll) jitter of this frame, radians.
    T_ego_camera : (4, 4) float64
        Camera (optical frame) pose in the ego frame, jitter included.
    """

    index: int
    s: float
    t: float
    T_world_ego: np.ndarray
    camera_jitter: tuple[float, float, float]
    T_ego_camera: np.ndarray

    @property
    def T_world_camera(self) -> np.ndarray:
        """Camera (optical) pose in the world frame."""
        return self.T_world_ego @ self.T_ego_camera


def camera_jitter(spec: SceneSpec, index: int) -> tuple[float, float, float]:
    """The (yaw, pitch, roll) jitter of frame ``index`` in radians, uniform within the spec bounds."""
    g = stream(spec.seed, "frame", index, "camera")
    p = spec.paths
    bounds = np.radians([p.yaw_jitter_deg, p.pitch_jitter_deg, p.roll_jitter_deg])
    return tuple(float(v) for v in g.uniform(-bounds, bounds))


def ego_pose_at(scene: SceneModel, spec: SceneSpec, t: np.ndarray | float, route: int = 0) -> np.ndarray:
    """``T_world_ego`` at time(s) ``t`` (seconds) driving route ``route`` at the spec speed.

    Returns
    -------
    (k, 4, 4) float64
        One pose per time.
    """
    path = scene.paths[route]
    pos, hd = path.at(np.asarray(t, np.float64) * spec.paths.speed_mps)
    out = np.repeat(np.eye(4)[None], len(hd), 0)
    c, s = np.cos(hd), np.sin(hd)
    out[:, 0, 0], out[:, 0, 1], out[:, 1, 0], out[:, 1, 1] = c, -s, s, c
    out[:, :3, 3] = pos
    return out


def plan_frames(scene: SceneModel, spec: SceneSpec, n_frames: int, first: int = 0, route: int = 0) -> list[Frame]:
    """Frames ``first .. first + n_frames - 1`` along route ``route``.

    On a closed route the frames wrap around the loop; on an open route ``n_frames``
    is limited to what fits (a warning-free truncation is the caller's choice: check
    :func:`max_frames`).
    """
    cam = spec.sensors.camera
    frames = []
    for k in range(first, first + n_frames):
        s = k * spec.paths.spacing_m
        t = s / spec.paths.speed_mps
        jit = camera_jitter(spec, k)
        frames.append(Frame(k, s, t, ego_pose_at(scene, spec, t, route)[0], jit,
                            rig.camera_extrinsics(cam.xyz_m, cam.rpy_deg, jit)))
    return frames


def max_frames(scene: SceneModel, spec: SceneSpec, route: int = 0) -> int:
    """How many distinct frames fit on the route (a loop: one lap)."""
    path = scene.paths[route]
    return max(1, int(math.floor(path.length() / spec.paths.spacing_m)) + (0 if path.closed else 1))
