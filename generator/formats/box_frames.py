"""The reader's 3D box: one box in one frame, and the move to LiDAR, ego, camera or world frame.

A :class:`Box` read from a dataset (:class:`generator.dataset.Dataset`) is in the frame of the scan it
belongs to: the LiDAR frame at the instant ``t`` the box describes (for a sweep record the LiDAR's
observation time of the box, which is the frame the raw points of that object are in). It carries
the poses needed to move it: ``T_world_lidar`` at ``t`` and the sensor mounts ``T_ego_lidar``,
``T_ego_camera`` (the nominal camera 2 of the stereo pair; a seed-003 image's own camera is passed
as ``T_world_camera``).

Frames (all right-handed, metres): ``lidar`` and ``ego`` (x forward, y left, z up), ``world`` (z up),
``camera`` (optical: x right, y down, z forward).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from scipy.spatial.transform import Rotation

from generator.detection.frames import CORNER_SIGNS
from generator.errors import UserError

FRAMES = ("lidar", "ego", "world", "camera")


@dataclass
class Box:
    """A 3D box in ``frame``.

    Attributes
    ----------
    uid : int
        Track id, stable over the sequence.
    cls : str
        Box class (``generator/labels/detection.yaml``).
    center : (3,) float64
        Metres, in ``frame``.
    quaternion : (4,) float64
        Rotation (x, y, z, w) of the box axes (length, width, height) in ``frame``.
    size : (3,) float64
        Length, width, height, metres.
    points : int
        LiDAR points of its instance ids in the sweep (``num_lidar_pts``).
    frame : str
        One of :data:`FRAMES`.
    yaw : float
        Heading of the length axis about the frame's z axis (meaningful in lidar, ego, world).
    velocity : (3,) float64
        Ground velocity of the centre, m/s, in the frame's axes.
    attribute, kind : str
        nuScenes attribute; asset kind.
    t : float
        Instant the box describes, seconds.
    instance_ids : tuple of int
    T_world_lidar, T_ego_lidar, T_ego_camera : (4, 4) float64 or None
        Poses for :meth:`to` (None: a box read from OpenLABEL, which stays in its ego frame).
    """

    uid: int
    cls: str
    center: np.ndarray
    quaternion: np.ndarray
    size: np.ndarray
    points: int
    frame: str = "ego"
    yaw: float = 0.0
    velocity: np.ndarray = field(default_factory=lambda: np.zeros(3))
    attribute: str = ""
    kind: str = ""
    t: float = 0.0
    instance_ids: tuple = ()
    T_world_lidar: np.ndarray | None = None
    T_ego_lidar: np.ndarray | None = None
    T_ego_camera: np.ndarray | None = None

    @property
    def rotation(self) -> np.ndarray:
        """(3, 3) float64: columns are the length, width and height axes in :attr:`frame`."""
        return Rotation.from_quat(self.quaternion).as_matrix()

    def corners(self) -> np.ndarray:
        """(8, 3) float64 corners in :attr:`frame` (bottom face, then top; KITTI order)."""
        return (CORNER_SIGNS * (np.asarray(self.size) / 2)) @ self.rotation.T + self.center

    def contains(self, points: np.ndarray, margin: float = 0.0) -> np.ndarray:
        """(n,) bool: which (n, 3) points (in :attr:`frame`) lie in the box grown by ``margin`` metres."""
        local = (np.asarray(points, np.float64) - self.center) @ self.rotation
        return np.all(np.abs(local) <= np.asarray(self.size) / 2 + margin, axis=1)

    def T_world(self, frame: str, T_world_camera: np.ndarray | None = None) -> np.ndarray:
        """(4, 4) pose of ``frame`` in the world at the box's instant."""
        if frame == "world":
            return np.eye(4)
        if self.T_world_lidar is None:
            raise UserError("this box came from OpenLABEL without poses: it stays in its ego frame "
                            "(write the box file with generate to move boxes between frames)")
        if frame == "lidar":
            return self.T_world_lidar
        ego = self.T_world_lidar @ np.linalg.inv(self.T_ego_lidar)
        if frame == "ego":
            return ego
        if frame == "camera":
            return np.asarray(T_world_camera, np.float64) if T_world_camera is not None else ego @ self.T_ego_camera
        raise UserError(f"frame {frame!r}: use one of {', '.join(FRAMES)}")

    def to(self, frame: str, T_world_camera: np.ndarray | None = None) -> Box:
        """The same box in ``frame`` (``T_world_camera``: another camera than the nominal one, e.g. an image's)."""
        if frame == self.frame and T_world_camera is None:
            return self
        T = np.linalg.inv(self.T_world(frame, T_world_camera)) @ self.T_world(self.frame)
        R = T[:3, :3] @ self.rotation
        q = Rotation.from_matrix(R).as_quat()
        return replace(self, center=T[:3, :3] @ self.center + T[:3, 3], quaternion=q, frame=frame,
                       yaw=float(np.arctan2(R[1, 0], R[0, 0])), velocity=T[:3, :3] @ self.velocity)


def box_of_record(rec, info: dict) -> Box:
    """A :class:`Box` in the LiDAR frame at the record's instant (``info``: the box file's ``info``)."""
    L = rec.lidar()
    T_ego_lidar = np.asarray(info.get("T_ego_lidar", np.eye(4)), np.float64)
    T_ego_camera = np.asarray(info.get("T_ego_camera", np.eye(4)), np.float64)
    return Box(rec.track_id, rec.cls, L["center"], Rotation.from_matrix(L["rotation"]).as_quat(), L["size"],
               rec.num_lidar_pts, "lidar", L["yaw"], L["velocity"], rec.attribute, rec.kind, rec.t, rec.instance_ids,
               np.asarray(rec.T_world_lidar, np.float64), T_ego_lidar, T_ego_camera)
