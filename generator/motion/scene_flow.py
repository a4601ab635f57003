"""LiDAR scene flow: per point of sweep ``j``, where its surface is when sweep ``j + 1`` fires that column.

A point ``p`` of sweep ``j`` was fired at ``t_p = t_j + tau_p`` (``tau_p``: its column's firing
offset, 0 with motion skew off) and its ``x_p`` is in the LiDAR frame of that instant (the
``.bin`` convention, :mod:`generator.lidar.scan`). The same column of sweep ``j + 1`` fires at
``t_p + dt`` (``dt`` = the sweep period, 0.1 s). The surface point ``X_p`` (world) is then at
``X'_p = M X_p``: ``M = T_world_actor(t_p + dt) inv(T_world_actor(t_p))`` on an actor (its
instance id), the identity on the static town. Two flows per point, both in the frame ``x_p``
is in (the LiDAR at ``t_p``), metres:

* ``object`` -- the surface's own displacement ``R_p^T (X'_p - X_p)``: 0 on the static town;
* ``ego`` (with the ego's motion) -- ``inv(T_world_lidar(t_p + dt)) X'_p - x_p``: ``x_p + ego``
  is where sweep ``j + 1``'s raw coordinates (the LiDAR frame of its firing instant) put that
  surface; on the static town it is the ego's motion alone. ``ego = E_p (x_p + object) - x_p``
  with ``E_p = inv(T_world_lidar(t_p + dt)) T_world_lidar(t_p)``.

And a flag (:func:`next_sweep_flags`): whether sweep ``j + 1`` can see that surface point.
No ray is cast: the flag reads sweep ``j + 1``'s points.
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from generator.motion import kernels

#: Flag values (the 4th float of a scene-flow row, :mod:`generator.formats.scene_flow`).
SEEN, HIDDEN, GONE = 0, 1, 2

PoseFn = Callable[[np.ndarray], np.ndarray]
#: Tangent-of-elevation lookup bins of the panorama (the HDL-64E's 27 deg of view: ~0.003 deg each).
LUT_BINS = 8192


def _inv(T: np.ndarray) -> np.ndarray:
    out = np.repeat(np.eye(4)[None], len(T), 0)
    Rt = np.transpose(T[:, :3, :3], (0, 2, 1))
    out[:, :3, :3] = Rt
    out[:, :3, 3] = -np.einsum("kij,kj->ki", Rt, T[:, :3, 3])
    return out


def _yaw_poses(position: np.ndarray, heading: np.ndarray) -> np.ndarray:
    """(k, 4, 4) poses from positions and headings, as :meth:`generator.world.actors.Track.pose` builds them."""
    out = np.repeat(np.eye(4)[None], len(heading), 0)
    c, s = np.cos(heading), np.sin(heading)
    out[:, 0, 0], out[:, 0, 1], out[:, 1, 0], out[:, 1, 1] = c, -s, s, c
    out[:, :3, 3] = position
    return out


class View:
    """The sensor's view as the flags read it: beam elevations, azimuth cells, range.

    The next sweep's points go into a range panorama (rows: the beams' elevations; columns: the
    sensor's azimuth steps; each cell the nearest return whose direction from the beams' mean
    emission point falls in it), against which each moved point is judged (:func:`next_sweep_flags`).

    Parameters
    ----------
    sensor : generator.lidar.sensors.Sensor
    origin_z : float, optional
        Height of the beams' mean emission point above the sensor origin (default from the sensor's
        vertical offsets), metres.
    """

    def __init__(self, sensor, origin_z: float | None = None):
        el = np.sort(np.asarray(sensor.elevation, np.float64))
        self.z0 = float(np.mean(sensor.vert_offset * np.cos(sensor.elevation))) if origin_z is None else origin_z
        half_top = (el[-1] - el[-2]) / 2 if len(el) > 1 else np.radians(1.0)
        half_bottom = (el[1] - el[0]) / 2 if len(el) > 1 else np.radians(1.0)
        top, bottom = float(np.tan(el[-1] + half_top)), float(np.tan(el[0] - half_bottom))
        self.t_lo, self.t_scale = bottom, LUT_BINS / (top - bottom)  # bins 0 .. LUT_BINS - 1 span the view
        t = self.t_lo + (np.arange(LUT_BINS) + 0.5) / self.t_scale
        tan_el = np.tan(el)
        self.lut_nearest = np.searchsorted((tan_el[1:] + tan_el[:-1]) / 2, t).astype(np.int64)
        self.lut_below = (np.searchsorted(tan_el, t, side="right") - 1).astype(np.int64)
        self.rows, self.steps = len(el), int(sensor.azimuth_steps)
        self.rmin, self.rmax = float(sensor.min_range_m), float(sensor.max_range_m)

    def cells(self, xyz: np.ndarray, pool=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(elevation bin, azimuth cell, range) of points ``xyz`` (3, n) float32 (:func:`kernels.directions`)."""
        n = xyz.shape[1]
        k, c, r = np.empty(n, np.int32), np.empty(n, np.int32), np.empty(n, np.float32)
        _split(lambda a, b: kernels.directions(xyz[:, a:b], self.z0, self.t_lo, self.t_scale, self.steps, k[a:b],
                                               c[a:b], r[a:b]), n, pool)
        return k, c, r

    def panorama(self, xyz: np.ndarray) -> np.ndarray:
        """(steps, rows) float32 range panorama of a sweep's points ``xyz`` (3, n) (inf: no return in a cell)."""
        pan = np.full((self.steps, self.rows), np.inf, np.float32)
        kernels.scatter_min(*self.cells(xyz), self.lut_nearest, pan)
        return pan

    def judge(self, moved: np.ndarray, pan: np.ndarray, pool=None) -> np.ndarray:
        """(n,) uint8 :data:`SEEN` / :data:`HIDDEN` / :data:`GONE` of moved points (3, n) against a panorama."""
        k, c, r = self.cells(moved, pool)
        out = np.empty(len(k), np.uint8)
        _split(lambda a, b: kernels.judge(k[a:b], c[a:b], r[a:b], pan, self.lut_below, self.rmin, self.rmax, out[a:b]),
               len(k), pool)
        return out


_NO_LOOKUP = np.full(1, -1, np.int64)


def _gather(x, y, z, instance, lookup) -> tuple[np.ndarray, np.ndarray]:
    """((3, n) float32 coordinates, rows on actors) of a sweep's fields: one pass over its records."""
    n = len(x)
    xyz, on = np.empty((3, n), np.float32), np.empty(n, np.uint8)
    inst = np.zeros(n, np.uint8) if instance is None else instance
    kernels.gather(x, y, z, inst, _NO_LOOKUP if lookup is None else lookup, xyz, on)
    return xyz, np.flatnonzero(on)


def _split(fn, n: int, pool) -> None:
    """``fn(start, stop)`` over rows ``0 .. n``: the second half on the pool's thread when there is one."""
    if pool is None or n < 4096:
        fn(0, n)
        return
    half = pool.submit(fn, n // 2, n)
    fn(0, n // 2)
    half.result()


def next_sweep_flags(moved: np.ndarray, next_xyz: np.ndarray, sensor) -> np.ndarray:
    """(n,) uint8 :data:`SEEN` / :data:`HIDDEN` / :data:`GONE`: can sweep ``j + 1`` see each moved point?

    ``moved`` (``x_p + ego``) and sweep ``j + 1``'s points are in the same convention (LiDAR frame at
    the firing instant), so they are compared in one range panorama of sweep ``j + 1``
    (:class:`View`). A point is

    * ``GONE`` when it is out of the sensor's view: nearer than its minimum or beyond its maximum
      range, or above the highest or below the lowest beam by more than half a beam spacing;
    * ``HIDDEN`` when the beams just above and just below its direction (in its azimuth cell) both
      return nearer than it, by more than ``max(0.25 m, 3 %)``: something stands in front;
    * ``SEEN`` otherwise (no nearer return in its direction: the next sweep sees that surface, or
      would, had the return not been dropped).

    Directions are taken from the beams' mean emission point, so within a few metres the beam a
    point falls between can be off by one: the flag is exact in the open and approximate on
    occlusion edges.
    """
    view = View(sensor)
    nxt = np.ascontiguousarray(np.asarray(next_xyz, np.float32).T)
    return view.judge(np.ascontiguousarray(np.asarray(moved, np.float32).T), view.panorama(nxt))


class SceneFlow:
    """The scene flow of a sequence's sweeps, one after the other (see the module docstring).

    Parameters
    ----------
    T_world_ego : callable
        ``(k,) seconds -> (k, 4, 4)`` ego world poses (the drive's ``T_world_ego``; a sampled drive's,
        :meth:`generator.world.actors.TrackTrajectory.T_world_ego`, is evaluated on its track's samples
        in one vectorised pass).
    T_ego_lidar : (4, 4) float64
        The LiDAR mount.
    actors : list of generator.world.actors.Actor
        The world's actors (empty for a frozen town).
    column_time : (steps,) float64
        Firing offset of each column after the sweep start, seconds (zeros with motion skew off).
    dt : float
        Time from a sweep's start to the next one's, seconds.
    view : View, optional
        The sensor's view (needed by :meth:`sweep` only).
    threads : int
        1 or 2: with 2 a helper thread builds the next sweep's panorama while this sweep's points
        move, and takes half of every per-point pass (the kernels release the GIL), as the scanner
        casts on two threads.

    Notes
    -----
    Each sweep's records are read twice (:mod:`generator.motion.kernels`): when it arrives as the
    *next* sweep (its panorama; which points are on actors) and when its own flow is computed. The
    ego poses at every column's instant ``dt`` later are the next sweep's own, so they are kept for
    it. Actor poses at the (actor, column) pairs hit come from one vectorised evaluation of all
    tracks (:class:`generator.lidar.tracks.TrackBank`, bit-identical to
    :meth:`generator.world.actors.Track.pose`).
    """

    def __init__(self, T_world_ego: PoseFn, T_ego_lidar: np.ndarray, actors: list, column_time: np.ndarray, dt: float,
                 view: View | None = None, threads: int = 2, prototypes: dict | None = None):
        from generator.lidar.tracks import TrackBank

        #: walkers (index into ``actors``: actor), whose limbs move their points too
        self._walkers = {i: a for i, a in enumerate(actors) if getattr(a, "gait", None) is not None and prototypes}
        self._prototypes = prototypes

        self.T_world_ego, self.dt, self.view = T_world_ego, float(dt), view
        self.T_ego_lidar = np.ascontiguousarray(T_ego_lidar, np.float64)
        self.column_time = np.asarray(column_time, np.float64)
        self.steps = len(self.column_time)
        ids = np.array([a.instance_id for a in actors], np.int64)
        self.lookup = np.full(int(ids.max()) + 1 if len(ids) else 1, -1, np.int64)
        self.lookup[ids] = np.arange(len(ids))
        self.bank = TrackBank([a.track for a in actors]) if len(actors) else None
        track = getattr(getattr(T_world_ego, "__self__", None), "track", None)  # TrackTrajectory.T_world_ego
        self._ego_bank = TrackBank([track]) if track is not None else None
        self._poses: tuple[float, np.ndarray] | None = None
        self._next: tuple | None = None  # (records, coordinates, actor rows) of the last sweep seen as the next one
        self._pool = ThreadPoolExecutor(1, thread_name_prefix="scene-flow") if threads > 1 else None

    @classmethod
    def for_rig(cls, rig, actors: list, sensor, motion_skew: bool, dt: float, threads: int = 2,
                prototypes: dict | None = None) -> SceneFlow:
        """The scene flow of ``sensor``'s sweeps on ``rig`` (:class:`generator.world.rig.Rig` with its drive;
        columns at their own instants when ``motion_skew``); ``prototypes`` (the world's) let a walker's
        points move with their limbs."""
        ct = sensor.column_time() if motion_skew else np.zeros(sensor.azimuth_steps)
        return cls(rig.trajectory.T_world_ego, rig.T_ego_lidar, actors, ct, dt, View(sensor), threads, prototypes)

    def close(self) -> None:
        """Stop the helper thread."""
        if self._pool is not None:
            self._pool.shutdown()
            self._pool = None

    def __enter__(self) -> SceneFlow:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def _ego_poses(self, t: float) -> np.ndarray:
        """(steps, 4, 4) ego poses at every column's instant of a sweep starting at ``t``."""
        if self._poses is not None and self._poses[0] == t:
            return self._poses[1]
        times = t + self.column_time
        if self._ego_bank is not None:  # a sampled track: one vectorised evaluation, as Track.pose computes it
            return _yaw_poses(*self._ego_bank.position_heading(np.zeros(len(times), np.int64), times))
        return self.T_world_ego(times)

    def _moves(self, column, instance, t_sweep: float, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(E per column, L per (actor, column) pair, each point's row of L) of a sweep."""
        P = self._ego_poses(t_sweep)
        Q = self._ego_poses(t_sweep + self.dt)
        self._poses = (t_sweep + self.dt, Q)
        E = np.empty((self.steps, 3, 4))
        kernels.relative_poses(P, Q, self.T_ego_lidar, E)
        which = np.zeros(len(column), np.int64)
        L = np.zeros((1, 3, 4))
        if len(rows) and self.bank is not None:
            col = np.asarray(column)[rows].astype(np.int64)
            key = self.lookup[np.asarray(instance)[rows]] * self.steps + col
            pairs, back = np.unique(key, return_inverse=True)
            actor, pcol = pairs // self.steps, pairs % self.steps
            t = t_sweep + self.column_time[pcol]
            A0 = _yaw_poses(*self.bank.position_heading(actor, t))
            A1 = _yaw_poses(*self.bank.position_heading(actor, t + self.dt))
            Tc = P[pcol] @ self.T_ego_lidar
            L = np.concatenate([L, (_inv(Tc) @ A1 @ _inv(A0) @ Tc)[:, :3, :]])
            which[rows] = 1 + back
        return E, np.ascontiguousarray(L), which

    def _apply(self, xyz, column, instance, t_sweep: float, rows) -> tuple[np.ndarray, np.ndarray]:
        E, L, which = self._moves(column, instance, t_sweep, rows)
        n = len(which)
        obj, moved = np.empty((n, 3), np.float32), np.empty((3, n), np.float32)
        _split(lambda a, b: kernels.apply_flows(xyz[:, a:b], column[a:b], which[a:b], E, L, obj[a:b], moved[:, a:b]), n,
               self._pool)
        if self._walkers and len(rows):
            from generator.motion.articulation import limb_flows

            limb_flows(self._walkers, self._prototypes, self.lookup, self.column_time + t_sweep, self.dt,
                       self._ego_poses(t_sweep) @ self.T_ego_lidar, xyz, np.asarray(column), np.asarray(instance), rows,
                       E, obj, moved)
        return obj, moved

    def flow(self, x: np.ndarray, y: np.ndarray, z: np.ndarray, instance: np.ndarray, column: np.ndarray,
             t_sweep: float) -> tuple[np.ndarray, np.ndarray]:
        """``object`` flow and moved points (``x + ego``) of one sweep (no flags).

        Parameters
        ----------
        x, y, z : (n,) float32
            Points, LiDAR frame at each firing instant (record fields or columns: any strides).
        instance : (n,) integer
            Instance id per point.
        column : (n,) integer
            Firing column per point.
        t_sweep : float
            Sweep start, seconds.

        Returns
        -------
        object, moved : (n, 3) float32
        """
        xyz, rows = _gather(x, y, z, instance, self.lookup)
        obj, moved = self._apply(xyz, column, instance, t_sweep, rows)
        return obj, np.ascontiguousarray(moved.T)

    def sweep(self, points: np.ndarray, next_points: np.ndarray, t_sweep: float) -> tuple[np.ndarray, np.ndarray]:
        """``object`` flow (n, 3) float32 and flag (n,) uint8 of a sweep's point records against the next sweep's.

        ``points`` and ``next_points`` are point records with at least ``x, y, z, instance, column``
        (:data:`generator.lidar.points.POINT_DTYPE`), after the scan's processing (the rows the
        ``.bin`` holds). Called for consecutive sweeps, each sweep's records are read once as the
        next sweep and once as the current one; the next sweep's panorama is made on the helper
        thread while this one's points move.
        """
        fields = ("x", "y", "z", "instance")
        if self._next is not None and self._next[0] is points:
            xyz, rows = self._next[1], self._next[2]
        else:
            xyz, rows = _gather(*(points[f] for f in fields), self.lookup)

        def prepare():
            nxt, next_rows = _gather(*(next_points[f] for f in fields), self.lookup)
            return nxt, next_rows, self.view.panorama(nxt)

        pending = self._pool.submit(prepare) if self._pool is not None else None
        E, L, which = self._moves(points["column"], points["instance"], t_sweep, rows)
        n = len(which)
        obj, moved = np.empty((n, 3), np.float32), np.empty((3, n), np.float32)
        kernels.apply_flows(xyz, points["column"], which, E, L, obj, moved)
        nxt, next_rows, pan = pending.result() if pending is not None else prepare()
        self._next = (next_points, nxt, next_rows)
        return obj, self.view.judge(moved, pan, self._pool)


def scene_flow(xyz: np.ndarray, instance: np.ndarray, column: np.ndarray, column_time: np.ndarray, t_sweep: float,
               dt: float, rig, actors: list) -> tuple[np.ndarray, np.ndarray]:
    """``object`` and ``ego`` flows (n, 3) float32 of one sweep's points (see the module docstring).

    Parameters
    ----------
    xyz : (n, 3) float
        Points, LiDAR frame at each point's firing instant, metres.
    instance, column : (n,) integer
        Instance id and firing column per point.
    column_time : (steps,) float64
        Firing offset of each column after the sweep start, seconds (zeros with motion skew off).
    t_sweep, dt : float
        Sweep start and the time to the next sweep's start, seconds.
    rig : generator.world.rig.Rig
        With the drive (``T_world_ego``, ``T_ego_lidar``).
    actors : list of generator.world.actors.Actor
    """
    p = np.asarray(xyz, np.float32)
    with SceneFlow(rig.trajectory.T_world_ego, rig.T_ego_lidar, actors, column_time, dt, threads=1) as sf:
        obj, moved = sf.flow(p[:, 0], p[:, 1], p[:, 2], instance, column, t_sweep)
    return obj, (moved.astype(np.float64) - p).astype(np.float32)
