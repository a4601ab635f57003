"""One LiDAR sweep: sensor rays + sensor motion -> labelled points.

Motion convention (KITTI-like, NOT de-skewed)
---------------------------------------------
A sweep of frame ``k`` starts at ``t_k`` (:meth:`generator.world.rig.Rig.frame`) and lasts one
rotation. With motion skew on, column ``c`` is fired at ``t_k + c / (steps * rotation_hz)``
from the sensor pose at that instant, and its points keep the raw coordinates the sensor
measures: the emission point plus range times beam direction, in the sensor frame AT
FIRING TIME. The whole sweep is then filed under the pose at the sweep START
(``T_world_sensor`` of column 0, which is what ``poses.txt`` records), exactly as KITTI
stores its scans: a static wall seen late in the sweep appears shifted by the ego motion
since ``t_k`` (up to speed x 0.1 s at 10 Hz). Each point's ``time`` field gives its
firing offset, so a consumer can de-skew. With motion skew off every column is fired
from the pose at ``t_k`` and ``time`` is 0.

Moving actors (``world``): each firing column also sees every actor of the world where its
track puts it at that column's instant (skew off: at ``t0``), and the nearer of actor and
town wins (:mod:`generator.lidar.actors`). Actor points carry the prototype's class and
material, the actor's instance id, and ``moving`` = 1 when its planar speed at the firing
time exceeds :data:`generator.world.actors.MOVING_THRESHOLD_MPS`.

Point record: :data:`POINT_DTYPE` (:mod:`generator.lidar.points`, re-exported here).
Points are ordered by column (firing time), then ring.
"""

from __future__ import annotations

import itertools
import os
from collections.abc import Callable, Iterator
from concurrent.futures import ThreadPoolExecutor, wait
from dataclasses import dataclass
from typing import Self

import numpy as np

from generator.lidar.actors import ActorCaster
from generator.lidar.caster import RayCaster, make_caster
from generator.lidar.kernels import returns, world_rays
from generator.lidar.physical_chunk import FaceLookup, central_constants, run_physical_chunk
from generator.lidar.points import POINT_DTYPE, RecordTables
from generator.lidar.returns import ReturnModel
from generator.lidar.sensors import Sensor
from generator.lidar.sweep_flight import SweepInFlight

__all__ = ["POINT_DTYPE", "PendingScan", "Scan", "Scanner"]


@dataclass
class Scan:
    """The points of one sweep.

    Attributes
    ----------
    points : (n,) POINT_DTYPE
    T_world_sensor : (4, 4) float64
        Sensor pose at the sweep start (the pose the points are filed under).
    n_rays : int
        Rays fired (``rings * columns``).
    rings, columns : int
        Range-image shape.
    """

    points: np.ndarray
    T_world_sensor: np.ndarray
    n_rays: int
    rings: int
    columns: int

    @property
    def xyz(self) -> np.ndarray:
        """(n, 3) float32 sensor-frame coordinates."""
        p = self.points
        return np.stack([p["x"], p["y"], p["z"]], -1)

    def range_image(self) -> np.ndarray:
        """(rings, columns) float32 range per beam and firing column, metres; 0 where no return.

        Row = ring (0 = highest beam), column = firing column (not an azimuth bin): a laser's
        ``rot_correction`` (up to about +-10 deg on the HDL-64E) shifts its beam sideways, so
        an edge looks sheared across rows, as in the device's raw packet order.
        """
        img = np.zeros((self.rings, self.columns), np.float32)
        img[self.points["ring"], self.points["column"]] = self.points["range"]
        return img


class Scanner:
    """Casts a sensor's sweeps against one scene (and its moving actors), reusing every BVH.

    Parameters
    ----------
    scene : generator.world.scene.SceneModel
        Cast against ``scene.vertices`` / ``scene.faces`` (real geometry, not label proxies).
    sensor : Sensor
    threads : int, optional
        Worker threads (default: ``os.cpu_count()``).
    caster : RayCaster, optional
        A prebuilt caster over the same scene (default: Embree over ``scene``).
    chunks_per_thread : int, optional
        Work items per thread (small items balance load across threads). Default 4, or 2 with the
        physical model, whose chunks cost more each (a halo column each side, the actors' aim, a dozen
        compiled passes: ~0.5 ms of CPU per chunk on the default town): on 2 threads, 4 chunks of a
        physical sweep finish sooner than 8.
    world : generator.world.actors.World, optional
        Its ``actors`` move through every sweep (None, or a world without actors: the static
        town only, byte for byte the same points). The ego must not be one of them (its own
        body would surround the sensor).
    returns : ReturnModel, optional
        The physical return model (:mod:`generator.lidar.returns`); None (default) or an
        ``ideal`` model: every ray's first hit is a point, whatever the sensor table says.

    Notes
    -----
    Per sweep, each chunk of firing columns is rotated into the world in float32 relative
    to the caster's re-centring point (:func:`generator.lidar.kernels.world_rays`) (the float64 pose
    translation minus the centre is taken first, so nothing large is ever rounded), cast against the town,
    then against the actors that can reach it (their plan is computed on the calling thread while the workers
    cast the town), and turned into records (:meth:`generator.lidar.points.RecordTables.fill`)
    written straight into the sweep's array at the chunk's offset, which the chunk learns
    from the previous one once that one knows its hit count (chunks start in order, so
    nobody waits for long and no final concatenation runs on one thread). Every step
    releases the GIL, so chunks run in parallel threads.
    """

    def __init__(self, scene, sensor: Sensor, threads: int | None = None, caster: RayCaster | None = None,
                 chunks_per_thread: int | None = None, world=None, returns: ReturnModel | None = None):
        self.sensor = sensor
        self.threads = max(1, int(threads or os.cpu_count() or 1))
        self.caster = caster if caster is not None else make_caster(scene)
        self.returns = returns if returns is not None and returns.params.physical else None
        n_static = len(self.caster.face_normals)
        spread = self.returns.spread if self.returns is not None else 0.0
        self.actors = (ActorCaster(world, sensor, n_static, self.caster.center, spread,
                                   getattr(self.caster, "native", None))
                       if world is not None and world.actors else None)
        # face-table rows: the town's faces, then each prototype's (instance filled per hit)
        protos = self.actors.protos if self.actors is not None else []
        self._records = RecordTables(
            sensor, np.concatenate([scene.face_class, *(m.face_class for m in protos)]),
            np.concatenate([scene.face_instance, *(np.zeros(m.n_faces, np.uint16) for m in protos)]),
            np.concatenate([scene.face_material, *(m.face_material for m in protos)]),
            np.concatenate([self.caster.face_normals, *(self.actors.face_normals() if protos else [])]))
        self._o32, self._d32 = self._records.origins, self._records.directions  # (steps, L, 3), ring order
        #: what the physical chunks read per face-table row (None without the physical model)
        self.face_lookup = (FaceLookup(self._records._faces, self.returns.optics,
                                       self.caster.triangle_corners())
                            if self.returns is not None else None)
        steps = sensor.azimuth_steps
        if chunks_per_thread is None:
            chunks_per_thread = 2 if self.returns is not None else 4
        n_chunks = min(steps, self.threads * max(1, chunks_per_thread))
        edges = np.linspace(0, steps, n_chunks + 1).round().astype(int)
        self._chunks = [slice(a, b) for a, b in itertools.pairwise(edges) if b > a]
        #: the central rays' offsets, transmissions and beams of the largest chunk (physical returns only)
        self.central_constants = (central_constants(max(c.stop - c.start for c in self._chunks) * sensor.n_lasers)
                                  if self.returns is not None else None)
        self._pool = ThreadPoolExecutor(self.threads, thread_name_prefix="lidar") if self.threads > 1 else None

    def close(self) -> None:
        """Stop the worker threads."""
        if self._pool is not None:
            self._pool.shutdown()
            self._pool = None

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def scan(self, T_world_sensor: np.ndarray, t0: float | None = None, alpha_per_m: float = 0.0,
             noise_key: int = 0) -> Scan:
        """Cast one sweep (:meth:`submit` and wait for it).

        Parameters
        ----------
        T_world_sensor : (4, 4) or (steps, 4, 4) float64
            One pose for the whole sweep (motion skew off) or one pose per firing column
            (motion skew on; column 0 is the sweep start), world frame.
        t0 : float, optional
            Sweep start on the world's clock, seconds: actors are posed at ``t0`` plus each
            column's firing offset (skew on) or at ``t0`` (skew off). Required when the
            scanner has actors.
        alpha_per_m : float
            Atmospheric extinction of this sweep, 1/m (physical returns only; fog and rain).
        noise_key : int
            Key of this sweep's range noise (physical returns only; :func:`generator.lidar.returns.frame_key`).

        Returns
        -------
        Scan
        """
        return self.submit(T_world_sensor, t0, alpha_per_m, noise_key).result()

    def submit(self, T_world_sensor: np.ndarray, t0: float | None = None, alpha_per_m: float = 0.0,
               noise_key: int = 0) -> PendingScan:
        """Start casting one sweep (arguments as :meth:`scan`); :meth:`PendingScan.result` gives its points.

        The sweep's chunks queue behind those of sweeps submitted before, so a caller that submits
        sweep ``k + 1`` before it reads sweep ``k`` keeps both threads busy across the sweep boundary
        (and while it writes sweep ``k``). Each sweep's points are the same whatever is in flight beside it.
        Returns once the actors' plan of the sweep is made (on the calling thread, while the workers cast).
        """
        poses = np.asarray(T_world_sensor, np.float64)
        skew = poses.ndim == 3
        if skew and len(poses) != self.sensor.azimuth_steps:
            raise ValueError(f"need one pose per column ({self.sensor.azimuth_steps}), got {len(poses)}")
        if self.actors is not None and t0 is None:
            raise ValueError("this scanner has moving actors: scan(..., t0=sweep start time) is required")
        steps = self.sensor.azimuth_steps
        rot_t = np.swapaxes(poses[..., :3, :3], -1, -2).astype(np.float32)
        trans = (poses[..., :3, 3] - self.caster.center).astype(np.float32)  # float64 difference first
        # one rotation and translation per column (repeated when the whole sweep has one pose)
        rot_t = np.ascontiguousarray(np.broadcast_to(rot_t, (steps, 3, 3)))
        trans = np.ascontiguousarray(np.broadcast_to(trans, (steps, 3)))
        per_beam = 2 if self.returns is not None and self.returns.params.mode == "dual" else 1
        sweep = SweepInFlight(np.empty(per_beam * self.sensor.rays_per_sweep, POINT_DTYPE), len(self._chunks), rot_t,
                              trans, skew, float(alpha_per_m), int(noise_key))

        def plan():  # which actors each column may see; the workers need it only after their static cast
            if self.actors is None:
                return None
            return self.actors.plan(poses, float(t0), self.sensor.column_time() if skew else None)

        futures = []
        if self._pool is None:
            sweep.set_plan(plan)
            sweep.raise_plan_error()
            for i, cols in enumerate(self._chunks):
                self._run_chunk(sweep, i, cols)
        else:
            futures = [self._pool.submit(self._run_chunk, sweep, i, cols) for i, cols in enumerate(self._chunks)]
            sweep.set_plan(plan)
        return PendingScan(self, sweep, futures, poses[0] if skew else poses)

    def sweep(self, rig, t0: float, motion_skew: bool = True, alpha_per_m: float = 0.0, noise_key: int = 0) -> Scan:
        """Cast the sweep starting at ``t0`` seconds from ``rig``'s LiDAR.

        Parameters
        ----------
        rig : generator.world.rig.Rig
            A rig with a trajectory.
        t0 : float
            Sweep start, seconds (the same clock as the world's actors).
        motion_skew : bool
            Fire each column from the pose of its own instant (a real spinning sensor), or
            every column from the pose at ``t0`` (and every actor at ``t0``).
        alpha_per_m, noise_key
            As :meth:`scan`.
        """
        return self.submit_sweep(rig, t0, motion_skew, alpha_per_m, noise_key).result()

    def submit_sweep(self, rig, t0: float, motion_skew: bool = True, alpha_per_m: float = 0.0,
                     noise_key: int = 0) -> PendingScan:
        """:meth:`sweep` without waiting for it (see :meth:`submit`)."""
        return self.submit(rig.sweep_poses(t0, self.sensor.column_time() if motion_skew else None), t0=t0,
                           alpha_per_m=alpha_per_m, noise_key=noise_key)

    def stream(self, n: int, start: Callable[[int], PendingScan]) -> Iterator[Scan]:
        """The scans of ``start(0) .. start(n - 1)`` in order, sweep ``j + 1`` started before sweep ``j`` is
        handed out: its chunks queue behind ``j``'s, so no thread waits at a sweep boundary or while the
        caller writes sweep ``j``.

        Parameters
        ----------
        n : int
            Sweeps.
        start : callable
            ``start(j)`` submits sweep ``j`` (:meth:`submit` or :meth:`submit_sweep`) and returns its
            :class:`PendingScan`.
        """
        ahead = [start(0)] if n > 0 else []
        for j in range(n):
            if j + 1 < n:
                ahead.append(start(j + 1))
            yield ahead.pop(0).result()

    def _run_chunk(self, sweep: SweepInFlight, i: int, cols: slice) -> None:
        if self.returns is not None:
            run_physical_chunk(self, sweep, i, cols)
            return
        try:
            n = (cols.stop - cols.start) * self.sensor.n_lasers
            o_w, d_w = np.empty((n, 3), np.float32), np.empty((n, 3), np.float32)
            world_rays(self._o32, self._d32, sweep.rot_t, sweep.trans, cols.start, cols.stop, o_w, d_w)
            # a miss keeps the max range as its distance until returns() marks it: nothing nearer
            dist, face = self.caster.intersect_local(o_w, d_w, self.sensor.max_range_m, mark_misses=False)
            on_actor = None
            plan = sweep.get_plan()
            if plan is not None:
                on_actor = self.actors.cast(plan, cols, o_w, d_w, dist, face)
            hit = np.empty(n, np.int64)
            hit = hit[:returns(dist, face, self.sensor.min_range_m, hit)]
            start = sweep.claim(i, len(hit))
        except BaseException:
            sweep.fail(i)
            raise
        out = sweep.out[start:start + len(hit)]
        self._records.fill(out, hit, cols.start * self.sensor.n_lasers, dist, face, d_w, sweep.skew)
        if on_actor is not None:
            actor, moving = on_actor
            a = actor.take(hit)
            m = np.flatnonzero(a >= 0)
            out["instance"][m] = self.actors.instance[a[m]]
            out["moving"][m] = moving.take(hit)[m]


class PendingScan:
    """A sweep :meth:`Scanner.submit` started; :meth:`result` waits for its points."""

    def __init__(self, scanner: Scanner, sweep: SweepInFlight, futures: list, T_world_sensor: np.ndarray):
        self._scanner, self._sweep, self._futures, self._pose = scanner, sweep, futures, T_world_sensor

    def result(self) -> Scan:
        """The sweep's :class:`Scan` (raises what a chunk or the actors' plan raised)."""
        wait(self._futures)
        self._sweep.raise_plan_error()
        for f in self._futures:
            f.result()
        s = self._scanner.sensor
        return Scan(self._sweep.out[:self._sweep.ends[-1]], self._pose, s.rays_per_sweep, s.n_lasers, s.azimuth_steps)
