"""Per-sweep 3D box records: every boxed thing seen by a LiDAR sweep, as detection datasets draw them.

One :class:`BoxRecord` per subject (:mod:`generator.detection.subjects`) and sweep: its box,
velocity, acceleration, nuScenes attribute, a stable ``track_id`` and ``num_lidar_pts``, the points
of its instance ids in that sweep's own labels (vehicle and rider of a ridden two-wheeler summed).

**The instant of a box.** A spinning LiDAR sees each object when its beam passes it, not at the
sweep start. With motion skew on (``lidar_meta.json`` ``motion_skew``), a record describes its
subject at the *observation time* ``t``: the sweep start plus the firing offset of the column
looking at the box centre (:class:`SweepClock`), found from the LiDAR pose at that instant (two
fixed-point steps; the column is within one step of the fixed point). The raw scan keeps every point
in the LiDAR frame of its firing instant (KITTI's convention), so in ``T_world_lidar`` (the LiDAR
pose at ``t``, carried by the record) the box and the raw points of its object agree up to the few
milliseconds the beam needs to cross the object. With motion skew off, ``t`` is the sweep start.
An object straddling the sweep's start azimuth (straight back) is seen at both ends of the sweep;
its box is at the instant of its centre's column.

Frames: centre, yaw, velocity and acceleration are stored in the world frame (z up, metres,
seconds); :meth:`BoxRecord.in_frame` and :meth:`BoxRecord.lidar` move them to any other.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from generator.detection.frames import box_in_frame, yaw_in


@dataclass(frozen=True)
class SweepClock:
    """When a spinning LiDAR fires at an azimuth.

    Column ``c`` of a sweep fires ``c * period / steps`` seconds after the sweep start, at the encoder
    azimuth ``start + sign * 2 pi c / steps`` (sign -1 clockwise), in the LiDAR frame (x forward,
    y left, z up).
    """

    start_azimuth_rad: float
    clockwise: bool
    period_s: float

    @classmethod
    def of(cls, sensor) -> SweepClock:
        """The clock of a :class:`generator.lidar.sensors.Sensor`."""
        return cls(float(sensor.start_azimuth_rad), bool(sensor.clockwise), float(sensor.period_s))

    def offset(self, azimuth: float) -> float:
        """Seconds after the sweep start when the beam points at ``azimuth`` (radians, LiDAR frame)."""
        sign = -1.0 if self.clockwise else 1.0
        return float(np.mod(sign * (azimuth - self.start_azimuth_rad), 2 * np.pi) / (2 * np.pi) * self.period_s)


@dataclass(frozen=True)
class BoxRecord:
    """One subject's 3D box in one sweep.

    Attributes
    ----------
    sweep : int
        Sweep index in the sequence (``NNNNNN`` of the scan).
    t : float
        Instant the box describes, seconds on the world timeline (``times.txt``; see the module docstring).
    track_id : int
        Stable over the sequence (the instance id of the object naming the box).
    instance_ids : tuple of int
        Instance ids of the box's points and pixels (a ridden two-wheeler: vehicle and rider).
    cls : str
        Box class, a native thing class (``generator/labels/detection.yaml``).
    kind : str
        Asset kind (``"car"``, ``"box_van"``, ``"bicyclist"``...).
    name : str
        Scene object or actor name.
    center : (3,) float64
        Box centre, world frame, metres.
    size : (3,) float64
        Length (along the heading), width, height, metres.
    yaw : float
        Heading of the length axis, world frame, radians counter-clockwise from +x.
    velocity, acceleration : (3,) float64
        Of the box centre over ground at ``t``, world frame, m/s and m/s^2.
    moving : bool
        Faster than 0.3 m/s at ``t`` (the rule of the LiDAR moving-* ids).
    attribute : str
        nuScenes attribute (``vehicle.parked``, ``cycle.with_rider``, ``pedestrian.standing``...).
    num_lidar_pts : int
        Points of ``instance_ids`` in the sweep's labels; -1 when no scan was counted (:func:`boxes_at`).
    T_world_lidar : (4, 4) float64
        LiDAR pose at ``t``: the frame the raw points of this object are in.
    static : bool
        Part of the static town.
    """

    sweep: int
    t: float
    track_id: int
    instance_ids: tuple[int, ...]
    cls: str
    kind: str
    name: str
    center: np.ndarray
    size: np.ndarray
    yaw: float
    velocity: np.ndarray
    acceleration: np.ndarray
    moving: bool
    attribute: str
    num_lidar_pts: int
    T_world_lidar: np.ndarray
    static: bool = False

    def in_frame(self, T_dst_world: np.ndarray) -> dict:
        """The box in frame ``dst`` (``T_dst_world`` (4, 4) maps world points into it).

        Returns
        -------
        dict
            ``center`` (3,), ``rotation`` (3, 3) (columns: length, width, height axes), ``yaw`` about
            ``dst``'s z, ``size`` (3,), ``velocity`` and ``acceleration`` (3,) rotated into ``dst``
            (ground motion, not relative to a moving frame).
        """
        c, R = box_in_frame(self.center, self.yaw, T_dst_world)
        Rd = np.asarray(T_dst_world, np.float64)[:3, :3]
        return {"center": c, "rotation": R, "yaw": yaw_in(R), "size": np.asarray(self.size, np.float64),
                "velocity": Rd @ self.velocity, "acceleration": Rd @ self.acceleration}

    def lidar(self) -> dict:
        """The box in the LiDAR frame at ``t`` (:meth:`in_frame` of ``inv(T_world_lidar)``)."""
        return self.in_frame(np.linalg.inv(self.T_world_lidar))


def instance_counts(instance: np.ndarray) -> dict[int, int]:
    """Points per instance id (> 0) of one scan's labels ((n,) uint16/uint32 instance ids)."""
    c = np.bincount(np.asarray(instance).astype(np.int64).reshape(-1))
    return {int(i): int(c[i]) for i in np.flatnonzero(c) if i > 0}


def observation_time(subject, t0: float, lidar_pose, clock: SweepClock | None) -> float:
    """When the sweep starting at ``t0`` sees ``subject``'s box centre (``t0`` without a clock).

    Parameters
    ----------
    lidar_pose : callable
        ``t -> (4, 4) T_world_lidar`` at ``t`` seconds.
    """
    if clock is None:
        return float(t0)
    t = float(t0)
    for _ in range(2):
        T = np.linalg.inv(lidar_pose(t))
        c = T[:3, :3] @ np.asarray(subject.box(t).center, np.float64) + T[:3, 3]
        t = float(t0) + clock.offset(float(np.arctan2(c[1], c[0])))
    return t


def record(subject, sweep: int, t: float, T_world_lidar: np.ndarray, n_points: int) -> BoxRecord:
    """The :class:`BoxRecord` of ``subject`` at ``t`` (every field from the world at that instant)."""
    box = subject.box(t)
    v, a = subject.motion(t)
    return BoxRecord(int(sweep), float(t), subject.track_id, subject.instance_ids, subject.cls, subject.kind,
                     subject.name, np.asarray(box.center, np.float64), np.asarray(box.size, np.float64),
                     float(box.yaw), v, a, subject.moving(t), subject.attribute(t), int(n_points),
                     np.asarray(T_world_lidar, np.float64), subject.static)


def sweep_boxes(subjects, sweep: int, t0: float, lidar_pose, counts: dict[int, int],
                clock: SweepClock | None = None, min_points: int = 1) -> list[BoxRecord]:
    """Box records of one sweep: every subject with at least ``min_points`` points in it.

    Parameters
    ----------
    subjects : list of generator.detection.subjects.Subject
    sweep : int
        Sweep index.
    t0 : float
        Sweep start, seconds on the world timeline.
    lidar_pose : callable
        ``t -> (4, 4) T_world_lidar``.
    counts : dict of int to int
        Points per instance id in the sweep's labels (:func:`instance_counts`).
    clock : SweepClock, optional
        The LiDAR's firing clock when motion skew is on (boxes at their observation time); None: at ``t0``.
    min_points : int
        Keep subjects with at least this many points (default 1: every object that appears in the
        cloud, as seed 002 does; 0 keeps every subject of the world).

    Returns
    -------
    list of BoxRecord, by ``track_id``.
    """
    out = []
    for s in subjects:
        n = sum(counts.get(i, 0) for i in s.instance_ids)
        if n < min_points:
            continue
        t = observation_time(s, t0, lidar_pose, clock)
        out.append(record(s, sweep, t, lidar_pose(t), n))
    return out


def boxes_at(subjects, t: float, lidar_pose=None, sweep: int = -1) -> list[BoxRecord]:
    """Every subject's record at one instant ``t`` (no point counts: ``num_lidar_pts`` -1).

    For consumers that need one instant for all boxes (an image's exposure, a nuScenes sample time).
    ``lidar_pose``: ``t -> T_world_lidar`` for the records' ``T_world_lidar`` (identity without).
    """
    T = np.eye(4) if lidar_pose is None else lidar_pose(t)
    return [record(s, sweep, t, T, -1) for s in subjects]
