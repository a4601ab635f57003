"""The world in time: the static town plus actors whose poses are functions of time.

Every sensor asks the same question -- :meth:`World.T_world_actor` at its own instant -- so
the camera and the LiDAR can never disagree about where a car was. Pure numpy.

A :class:`Track` is a mover's pose sampled every ``dt`` seconds from ``t0``; between samples
position and heading are linear in time (the heading along the shorter arc), so a pose is
exact for any instant and velocity is piecewise constant. Velocity and acceleration reported
to users (OpenLABEL, metadata) are central differences of the samples, the same numbers a
finite difference of cuboid centres gives.

Frames: world frame (z up, metres); an actor's local frame has x forward, y left, z up,
origin on the ground under the reference point of its prototype (as static objects).
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field

import numpy as np

from generator.errors import UserError
from generator.geometry import Mesh
from generator.world.gait import Gait
from generator.world.scene import OrientedBox, SceneModel

#: An actor faster than this at an instant is *moving* there (SemanticKITTI moving-* ids,
#: OpenLABEL ``moving``); a pedestrian standing or a car waiting at a stop line is not.
MOVING_THRESHOLD_MPS = 0.3


@dataclass(frozen=True)
class Track:
    """A pose sampled every ``dt`` seconds.

    Attributes
    ----------
    t0 : float
        Time of the first sample, seconds.
    dt : float
        Sample spacing, seconds.
    xyz : (T, 3) float64
        Positions of the local origin, world frame, metres.
    yaw : (T,) float64
        Heading, radians, unwrapped (continuous from sample to sample).
    """

    t0: float
    dt: float
    xyz: np.ndarray
    yaw: np.ndarray

    @property
    def t1(self) -> float:
        """Time of the last sample."""
        return self.t0 + self.dt * (len(self.yaw) - 1)

    def _where(self, t) -> tuple[np.ndarray, np.ndarray]:
        x = (np.atleast_1d(np.asarray(t, np.float64)) - self.t0) / self.dt
        x = np.clip(x, 0.0, len(self.yaw) - 1.0)
        i = (
            np.minimum(np.floor(x).astype(np.int64), len(self.yaw) - 2)
            if len(self.yaw) > 1
            else np.zeros(len(x), np.int64)
        )
        return i, x - i

    def position(self, t) -> np.ndarray:
        """(k, 3) float64 positions at time(s) ``t`` (clamped to the sampled span)."""
        if len(self.yaw) == 1:
            return np.repeat(self.xyz[:1], np.size(t), 0)
        i, f = self._where(t)
        return self.xyz[i] * (1 - f[:, None]) + self.xyz[i + 1] * f[:, None]

    def heading(self, t) -> np.ndarray:
        """(k,) float64 headings at time(s) ``t``, radians (unwrapped)."""
        if len(self.yaw) == 1:
            return np.repeat(self.yaw[:1], np.size(t))
        i, f = self._where(t)
        return self.yaw[i] * (1 - f) + self.yaw[i + 1] * f

    def pose(self, t) -> np.ndarray:
        """(k, 4, 4) float64 ``T_world_actor`` at time(s) ``t``."""
        p, h = self.position(t), self.heading(t)
        out = np.repeat(np.eye(4)[None], len(h), 0)
        c, s = np.cos(h), np.sin(h)
        out[:, 0, 0], out[:, 0, 1], out[:, 1, 0], out[:, 1, 1] = c, -s, s, c
        out[:, :3, 3] = p
        return out

    def velocity(self, t, h: float | None = None) -> np.ndarray:
        """(k, 3) float64 velocity, central difference over ``+-h`` seconds (default ``dt``), m/s."""
        h = self.dt if h is None else h
        t = np.atleast_1d(np.asarray(t, np.float64))
        return (self.position(t + h) - self.position(t - h)) / (2 * h)

    def acceleration(self, t, h: float | None = None) -> np.ndarray:
        """(k, 3) float64 acceleration, second central difference over ``+-h`` seconds, m/s^2."""
        h = self.dt if h is None else h
        t = np.atleast_1d(np.asarray(t, np.float64))
        return (self.position(t + h) - 2 * self.position(t) + self.position(t - h)) / (h * h)

    def speed(self, t) -> np.ndarray:
        """(k,) float64 speed, m/s."""
        return np.linalg.norm(self.velocity(t)[:, :2], axis=1)


@dataclass
class Actor:
    """One mover: a prototype mesh under a pose that changes with time.

    Attributes
    ----------
    uid : int
        Stable id for the whole sequence (0..n-1, the position in :attr:`World.actors`).
    name : str
        Unique, e.g. ``"actor_car_0003"``.
    kind : str
        ``"car"``, ``"truck"``, ``"bus"``, ``"ridden_bicycle"``, ``"person"`` ...
    cls : str
        Main native class (a ridden bicycle's is ``bicyclist``).
    instance_id : int
        Instance id, unique in the world (after the static town's), the same in every sweep.
    prototype : str
        Key into :attr:`World.prototypes`.
    size : (3,) float
        Box length, width, height, metres.
    box_center : (3,) float
        Box centre in the local frame, metres.
    track : Track
    proxy : str or None
        Key into :attr:`World.proxies`.
    attrs : dict
        Renderer parameters (``color``...).
    gait : Gait or None
        A walker's phase meshes (``prototype`` is then its phase-0 mesh; ``size`` and ``box_center``
        hold every phase: the box of the union); None for a rigid actor.
    """

    uid: int
    name: str
    kind: str
    cls: str
    instance_id: int
    prototype: str
    size: tuple[float, float, float]
    box_center: tuple[float, float, float]
    track: Track
    proxy: str | None = None
    attrs: dict = field(default_factory=dict)
    gait: Gait | None = None

    def prototype_at(self, t: float) -> str:
        """Key of the mesh the actor shows at time ``t`` (its gait phase mesh, or :attr:`prototype`)."""
        if self.gait is None:
            return self.prototype
        return self.gait.keys[int(self.gait.index(self.track, t)[0])]

    def local_box(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """(centre, size) (3,) float64 of the actor's box at ``t`` in its local frame: the extent of the
        mesh it shows then."""
        if self.gait is None:
            return np.asarray(self.box_center, np.float64), np.asarray(self.size, np.float64)
        k = int(self.gait.index(self.track, t)[0])
        return (self.gait.lo[k] + self.gait.hi[k]) / 2, self.gait.hi[k] - self.gait.lo[k]

    def rigid_center(self, t: float) -> np.ndarray:
        """(3,) float64 world position at ``t`` of :attr:`box_center` (for a rigid actor its box's centre;
        a walker's moves with its body, not with its limbs: what box velocities are taken of)."""
        T = self.track.pose(t)[0]
        return np.asarray(tuple(float(v) for v in T[:3, :3] @ np.asarray(self.box_center) + T[:3, 3]), np.float64)

    def box(self, t: float) -> OrientedBox:
        """The actor's oriented box at time ``t``, world frame (a walker's: the extent of its phase mesh then)."""
        T = self.track.pose(t)[0]
        centre, size = self.local_box(t)
        c = T[:3, :3] @ centre + T[:3, 3]
        return OrientedBox(tuple(float(v) for v in c), tuple(float(v) for v in size),
                           float(self.track.heading(t)[0]))


@dataclass
class World:
    """The static town, the actors and the ego's drive: everything at any time.

    Attributes
    ----------
    scene : SceneModel
        The static town (one BVH for the LiDAR, one Blender scene).
    actors : list of Actor
        Empty for a frozen town (``traffic`` densities all 0).
    prototypes, proxies : dict of str to Mesh
        Actor meshes (local frames) and their label proxies.
    ego : object
        The ego's trajectory: ``T_world_ego(t) -> (k, 4, 4)`` and ``knot_offsets(t0, period)``
        (:class:`generator.world.trajectory.EgoTrajectory` or :class:`TrackTrajectory`).
    duration_s : float
        Seconds of simulated time from 0 (poses beyond it are held).
    """

    scene: SceneModel
    actors: list[Actor]
    prototypes: dict[str, Mesh]
    proxies: dict[str, Mesh]
    ego: object
    duration_s: float

    def digest(self, times) -> str:
        """sha256 (hex) of every actor's identity and pose and the ego's pose at ``times`` (seconds).

        Recorded with a sequence (``lidar_meta.json`` ``traffic.digest``) so a world rebuilt
        from the spec later (fusion, OpenLABEL) is known to be the one the sensors saw. Poses are
        rounded to 1e-6 and negative zeros made positive, so the digest does not hang on the last
        bit: machines whose vectorised maths differs there (AVX-512 and AVX2 ``exp``, ``arctan2``...)
        agree on it.
        """
        return self._digest(times, signed_zeros=False)

    def _digest(self, times, signed_zeros: bool) -> str:
        t = np.round(np.asarray(times, np.float64).reshape(-1), 4)  # times.txt keeps 7 significant digits
        zero = -0.0 if signed_zeros else 0.0  # x + 0.0 turns -0.0 into 0.0; x + -0.0 keeps every bit

        def rounded(a: np.ndarray) -> bytes:
            return (np.round(a, 6) + zero).tobytes()

        h = hashlib.sha256(rounded(self.ego.T_world_ego(t)))
        for a in self.actors:
            h.update(f"{a.uid}/{a.instance_id}/{a.kind}/{a.cls}".encode())
            h.update(rounded(a.track.pose(t)))
        return h.hexdigest()

    def check_digest(self, recorded, times, source: str) -> None:
        """Refuse (one line) a rebuilt world whose :meth:`digest` differs from the ``recorded`` one.

        Nothing to check when nothing was recorded (a sequence from before digests); a digest
        recorded before negative zeros were folded is accepted too.
        """
        if recorded is None:
            return
        if recorded != self.digest(times) and recorded != self._digest(times, signed_zeros=True):
            raise UserError(f"{source}: traffic.digest: the traffic rebuilt from the spec is not the one this "
                            "sequence was cast in (another spec in manifest.json, or another version of urbangen's "
                            "traffic model); regenerate the sequence with this version")

    def T_world_actor(self, t: float) -> np.ndarray:
        """(n, 4, 4) float64 pose of every actor at time ``t`` (seconds)."""
        if not self.actors:
            return np.zeros((0, 4, 4))
        return np.stack([a.track.pose(t)[0] for a in self.actors])

    def velocities(self, t: float) -> np.ndarray:
        """(n, 3) float64 actor velocities at ``t``, m/s."""
        return np.array([a.track.velocity(t)[0] for a in self.actors]).reshape(-1, 3)

    def moving(self, t: float) -> np.ndarray:
        """(n,) bool: which actors move faster than :data:`MOVING_THRESHOLD_MPS` at ``t``."""
        v = self.velocities(t)
        return np.linalg.norm(v[:, :2], axis=1) > MOVING_THRESHOLD_MPS

    def boxes(self, t: float) -> list[OrientedBox]:
        """Every actor's box at ``t``."""
        return [a.box(t) for a in self.actors]


@dataclass(frozen=True)
class TrackTrajectory:
    """The ego's drive as a sampled track (traffic on): the ego is one of the movers.

    Same interface as :class:`generator.world.trajectory.EgoTrajectory`.

    Attributes
    ----------
    track : Track
        Pose of the ego frame's origin (ISO 8855: x forward, y left, z up).
    distance : (T,) float64
        Distance driven at each sample, metres (non-decreasing: the ego may stop).
    """

    track: Track
    distance: np.ndarray

    def T_world_ego(self, t) -> np.ndarray:
        """(k, 4, 4) float64 ego poses at time(s) ``t``."""
        return self.track.pose(t)

    def knot_offsets(self, t0: float, period_s: float) -> np.ndarray:
        """(k,) float64: 0, the track samples inside ``(t0, t0 + period)`` as offsets, ``period``.

        The pose is linear between samples, so poses at these offsets rebuild any instant exactly.
        """
        tr = self.track
        k = np.arange(int(np.floor((t0 - tr.t0) / tr.dt)), int(np.ceil((t0 + period_s - tr.t0) / tr.dt)) + 1)
        times = tr.t0 + k * tr.dt - t0
        eps = 1e-9  # a sample AT t0 or t0 + period (0.3 - 0.3 = 5.6e-17) is the start or end knot, not another
        inner = times[(times > eps) & (times < period_s - eps) & (k > 0) & (k < len(tr.yaw) - 1)]
        return np.unique(np.r_[0.0, inner, period_s])

    def time_at_distance(self, s: float) -> float:
        """First time the ego has driven ``s`` metres (linear between samples)."""
        d, tr = self.distance, self.track
        i = int(np.searchsorted(d, s, side="left"))
        if i <= 0:
            return tr.t0
        if i >= len(d):
            return tr.t1
        f = (s - d[i - 1]) / max(d[i] - d[i - 1], 1e-12)
        return tr.t0 + (i - 1 + f) * tr.dt

    def max_frames(self, spacing_m: float) -> int:
        """How many frames ``spacing_m`` apart the simulated drive reaches."""
        return max(1, int(np.floor(float(self.distance[-1]) / spacing_m)) + 1)

    def distance_at(self, t: float) -> float:
        """Metres driven at time ``t`` (linear between samples)."""
        tr = self.track
        return float(np.interp(t, tr.t0 + tr.dt * np.arange(len(self.distance)), self.distance))

    @property
    def speed_mps(self) -> float:
        """Mean speed over the drive (for messages), m/s."""
        return float(self.distance[-1] / max(self.track.t1 - self.track.t0, 1e-9))


def frozen_world(scene: SceneModel, ego) -> World:
    """A world without actors (traffic off): the static town and the ego's drive."""
    return World(scene, [], {}, {}, ego, float("inf"))
