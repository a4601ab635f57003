"""The sensor rig: every sensor's mount and intrinsics, and the ego's pose at any time.

One :class:`Rig` is built from the spec (and the scene, for the ego route); every consumer --
frame plan, LiDAR sweeps, KITTI calib and poses, OpenLABEL, the renderer -- reads it, so
they cannot disagree about where a sensor was.

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
from dataclasses import dataclass

import numpy as np

from generator.geometry.transforms import invert, mount, pose
from generator.rng import stream
from generator.world.trajectory import EgoTrajectory

__all__ = [
    "R_BODY_OPTICAL",
    "SWEEP_PERIOD_S",
    "Frame",
    "Rig",
    "camera_extrinsics",
    "ego_pose",
    "intrinsics",
    "invert",
    "mount",
    "pixel_rays",
    "pose",
]

#: One LiDAR sweep: sweeps start every 0.1 s (a 10 Hz spinning sensor, as KITTI's HDL-64E).
SWEEP_PERIOD_S = 0.1

#: Rotation taking optical-frame vectors (x right, y down, z forward) to body axes
#: (x forward, y left, z up): columns are the optical axes written in the body frame.
R_BODY_OPTICAL = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])


def ego_pose(position: np.ndarray, heading: float) -> np.ndarray:
    """``T_world_ego`` for an ego at ``position`` ((3,) world, metres) facing ``heading`` (rad)."""
    return pose(float(position[0]), float(position[1]), float(position[2]), yaw=float(heading))


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


def pixel_rays(k: np.ndarray, width: int, height: int) -> np.ndarray:
    """(height, width, 3) float64 unit ray directions through pixel centres, camera (optical) frame."""
    u, v = np.meshgrid(np.arange(width) + 0.5, np.arange(height) + 0.5)
    d = np.stack([(u - k[0, 2]) / k[0, 0], (v - k[1, 2]) / k[1, 1], np.ones_like(u)], -1)
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


@dataclass(frozen=True)
class Frame:
    """One dataset frame: where the ego is and how the camera is turned.

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


@dataclass(frozen=True)
class Rig:
    """Every sensor's mount and intrinsics, and the ego trajectory, from one spec.

    Frame ``k`` sits ``k * spacing_m`` metres along the route, reached at
    ``t_k = s_k / speed``. The LiDAR sweep of a frame starts at ``t_k`` and lasts one
    rotation while the ego keeps moving; the camera image is exposed at ``t_k``. The
    camera's random yaw / pitch / roll of frame ``k`` comes from the named stream
    ``("frame", k, "camera")``, so it never depends on how many frames are planned.

    Attributes
    ----------
    seed : int
        The spec's seed (for the per-frame camera jitter).
    camera_xyz_m, camera_rpy_deg : (3,) float
        Camera mount in the ego frame (body axes), metres and degrees.
    hfov_deg : float
        Camera horizontal field of view, degrees.
    jitter_deg : (3,) float
        Bounds of the per-frame camera (yaw, pitch, roll) jitter, degrees.
    T_ego_lidar : (4, 4) float64
        LiDAR mount (body axes: x forward, y left, z up).
    spacing_m : float
        Route distance between dataset frames, metres.
    baseline_m : float
        KITTI stereo pair: the right camera (``image_3``) sits this far right of the left one
        (``image_2``), which is the nominal camera mount without jitter.
    trajectory : EgoTrajectory or None
        The ego's drive; ``None`` for a rig built without a scene (mounts only).
    """

    seed: int
    camera_xyz_m: tuple[float, float, float]
    camera_rpy_deg: tuple[float, float, float]
    hfov_deg: float
    jitter_deg: tuple[float, float, float]
    T_ego_lidar: np.ndarray
    spacing_m: float
    baseline_m: float = 0.54
    trajectory: EgoTrajectory | None = None

    @classmethod
    def from_world(cls, spec, world) -> Rig:
        """The rig of ``spec`` riding the ego of ``world`` (:class:`generator.world.actors.World`)."""
        import dataclasses

        return dataclasses.replace(cls.from_spec(spec), trajectory=world.ego)

    @classmethod
    def from_spec(cls, spec, scene=None, route: int = 0) -> Rig:
        """The rig of ``spec`` driving route ``route`` of ``scene`` (mounts only without a scene)."""
        cam, lidar, p = spec.sensors.camera, spec.sensors.lidar, spec.paths
        traj = EgoTrajectory(scene.paths[route], p.speed_mps) if scene is not None else None
        return cls(spec.seed, tuple(cam.xyz_m), tuple(cam.rpy_deg), cam.hfov_deg,
                   (p.yaw_jitter_deg, p.pitch_jitter_deg, p.roll_jitter_deg), mount(lidar.xyz_m, lidar.rpy_deg),
                   p.spacing_m, spec.sensors.stereo.baseline_m, traj)

    # -- mounts and intrinsics ---------------------------------------------------------------
    def T_ego_camera(self, jitter_rad=(0.0, 0.0, 0.0)) -> np.ndarray:
        """(4, 4) camera (optical frame) pose in the ego frame, with a (yaw, pitch, roll) jitter."""
        return camera_extrinsics(self.camera_xyz_m, self.camera_rpy_deg, jitter_rad)

    def K(self, width: int, height: int) -> np.ndarray:
        """(3, 3) float64 camera intrinsics for a ``width`` x ``height`` image."""
        return intrinsics(self.hfov_deg, width, height)

    def T_camera_lidar(self) -> np.ndarray:
        """(4, 4) LiDAR -> nominal camera (no jitter): KITTI's ``Tr`` (velodyne -> cam0)."""
        return invert(self.T_ego_camera()) @ self.T_ego_lidar

    def T_ego_stereo(self, camera: int) -> np.ndarray:
        """(4, 4) optical-frame pose of KITTI camera 2 (left) or 3 (right) in the ego frame.

        Camera 2 is the nominal camera mount (no jitter) and the rectified reference frame;
        camera 3 is ``baseline_m`` to its right, same orientation (a rectified pair).
        """
        if camera not in (2, 3):
            raise ValueError(f"stereo camera must be 2 or 3, got {camera}")
        shift = np.eye(4)
        shift[0, 3] = self.baseline_m if camera == 3 else 0.0  # optical x points right
        return self.T_ego_camera() @ shift

    def stereo_projections(self, width: int, height: int) -> dict[str, np.ndarray]:
        """KITTI ``P0``..``P3`` (3, 4) float64 of the rectified pair, camera 2 the reference.

        ``P2 = P0 = K [I | 0]``; ``P3 = P1 = K [I | (-baseline, 0, 0)]`` (a point ``X`` in the
        camera-2 frame lands in image 3 at ``P3 X``). urbangen renders no grayscale pair, so
        cameras 0/1 coincide with 2/3.
        """
        k = self.K(width, height)
        left = np.hstack([k, np.zeros((3, 1))])
        right = np.hstack([k, (k @ np.array([-self.baseline_m, 0.0, 0.0]))[:, None]])
        return {"P0": left, "P1": right.copy(), "P2": left.copy(), "P3": right}

    # -- time ---------------------------------------------------------------------------------
    def _drive(self) -> EgoTrajectory:
        if self.trajectory is None:
            raise ValueError("this rig was built without a scene: it has mounts but no trajectory")
        return self.trajectory

    def T_world_ego(self, t: np.ndarray | float) -> np.ndarray:
        """(k, 4, 4) float64 ego poses at time(s) ``t`` (seconds)."""
        return self._drive().T_world_ego(t)

    def T_world_lidar(self, t: np.ndarray | float) -> np.ndarray:
        """(k, 4, 4) float64 LiDAR poses at time(s) ``t`` (seconds)."""
        return self.T_world_ego(t) @ self.T_ego_lidar

    def camera_jitter(self, index: int) -> tuple[float, float, float]:
        """The (yaw, pitch, roll) jitter of frame ``index`` in radians, uniform within the bounds."""
        g = stream(self.seed, "frame", index, "camera")
        bounds = np.radians(self.jitter_deg)
        return tuple(float(v) for v in g.uniform(-bounds, bounds))

    def frame(self, index: int) -> Frame:
        """Frame ``index``: where the ego has driven ``index * spacing_m`` metres (a loop wraps around).

        The frame time is the start of the LiDAR sweep nearest to that instant (a multiple of
        :data:`SWEEP_PERIOD_S`): the camera is exposed with a sweep, as KITTI triggers it, and
        image ``k`` pairs with sweep :meth:`sweep_of`.
        """
        drive = self._drive()
        t = round(round(drive.time_at_distance(index * self.spacing_m) / SWEEP_PERIOD_S) * SWEEP_PERIOD_S, 9)
        s = drive.distance_at(t)
        jit = self.camera_jitter(index)
        return Frame(index, s, t, self.T_world_ego(t)[0], jit, self.T_ego_camera(jit))

    @staticmethod
    def sweep_of(frame: Frame) -> int:
        """Index of the 10 Hz LiDAR sweep that starts when ``frame`` is exposed."""
        return round(frame.t / SWEEP_PERIOD_S)

    @staticmethod
    def sweep_time(j: int) -> float:
        """Start of sweep ``j``, seconds."""
        return round(j * SWEEP_PERIOD_S, 9)

    def frames(self, n_frames: int, first: int = 0) -> list[Frame]:
        """Frames ``first .. first + n_frames - 1`` (check :meth:`max_frames` on an open route)."""
        return [self.frame(k) for k in range(first, first + n_frames)]

    def max_frames(self) -> int:
        """How many distinct frames fit on the route (a loop: one lap)."""
        return self._drive().max_frames(self.spacing_m)

    def sweep_poses(self, t0: float, column_times: np.ndarray | None) -> np.ndarray:
        """LiDAR world poses of a sweep starting at ``t0`` seconds.

        Parameters
        ----------
        column_times : (steps,) float64 or None
            Firing offset of each column after ``t0`` (motion skew on), or ``None`` (skew off).

        Returns
        -------
        (steps, 4, 4) float64 with skew (one ``T_world_lidar`` per firing column), else (4, 4) at ``t0``.
        """
        if column_times is None:
            return self.T_world_lidar(np.array([t0], np.float64))[0]
        return self.T_world_lidar(t0 + np.asarray(column_times, np.float64))

    def sweep_record(self, t0: float, period_s: float) -> dict:
        """``{"t_s": [...], "T_world_lidar": [...]}``: LiDAR poses at the sweep's knots.

        The knots are the sweep start, every route sample crossed during the sweep and the
        sweep end: enough to rebuild the pose of any firing instant exactly
        (:func:`generator.fusion.projection.deskew`); ``t_s`` are offsets after ``t0``.
        """
        offsets = self._drive().knot_offsets(t0, period_s)
        poses = self.T_world_lidar(t0 + offsets)
        return {"t_s": np.round(offsets, 12).tolist(), "T_world_lidar": np.round(poses, 12).tolist()}
