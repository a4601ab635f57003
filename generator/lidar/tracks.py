"""Many actors' tracks evaluated at once: positions, headings and speeds at (actor, time) pairs.

A sweep asks where each of ~100 actors is at each of its ~50 visible firing columns; calling
:meth:`generator.world.actors.Track.pose` per actor costs ~20 us of Python each time, which
at 30 sweeps/s is a measurable share of a core. :class:`TrackBank` stacks the tracks that share
a time grid (``t0``, ``dt``, sample count -- every traffic model samples at the same
``generator.traffic.movers.DT_S``) into arrays and evaluates them with the SAME float64
operations as :class:`~generator.world.actors.Track`, so every pose and speed is bit-identical
to what ``actor.track.pose(t)`` / ``actor.track.speed(t)`` return (tested): the LiDAR and the
camera cannot disagree about where an actor was.
"""

from __future__ import annotations

import numpy as np


class TrackBank:
    """The tracks of a list of actors, grouped by time grid.

    Parameters
    ----------
    tracks : list of generator.world.actors.Track
        One per actor; actor ``a`` is ``tracks[a]``.
    """

    def __init__(self, tracks: list):
        self.n = len(tracks)
        groups: dict[tuple, list[int]] = {}
        for a, tr in enumerate(tracks):
            groups.setdefault((float(tr.t0), float(tr.dt), len(tr.yaw)), []).append(a)
        self._group_of = np.zeros(self.n, np.int64)
        self._row_of = np.zeros(self.n, np.int64)
        self._groups = []
        for g, ((t0, dt, n_samples), members) in enumerate(groups.items()):
            self._group_of[members] = g
            self._row_of[members] = np.arange(len(members))
            xyz = np.stack([np.asarray(tracks[a].xyz, np.float64) for a in members])  # (m, T, 3)
            yaw = np.stack([np.asarray(tracks[a].yaw, np.float64) for a in members])  # (m, T)
            self._groups.append((t0, dt, n_samples, xyz, yaw))

    # -- the Track arithmetic, vectorised over actors ---------------------------------------------
    @staticmethod
    def _where(t: np.ndarray, t0: float, dt: float, n_samples: int) -> tuple[np.ndarray, np.ndarray]:
        x = np.clip((t - t0) / dt, 0.0, n_samples - 1.0)
        i = np.minimum(np.floor(x).astype(np.int64), n_samples - 2) if n_samples > 1 else np.zeros(len(x), np.int64)
        return i, x - i

    def _eval(self, actors: np.ndarray, t: np.ndarray, want_heading: bool) -> tuple[np.ndarray, np.ndarray | None]:
        pos = np.empty((len(actors), 3))
        head = np.empty(len(actors)) if want_heading else None
        group = self._group_of[actors]
        for g, (t0, dt, n_samples, xyz, yaw) in enumerate(self._groups):
            sel = np.flatnonzero(group == g) if len(self._groups) > 1 else slice(None)
            rows, tt = self._row_of[actors[sel]], t[sel]
            if n_samples == 1:
                pos[sel] = xyz[rows, 0]
                if want_heading:
                    head[sel] = yaw[rows, 0]
                continue
            i, f = self._where(tt, t0, dt, n_samples)
            pos[sel] = xyz[rows, i] * (1 - f[:, None]) + xyz[rows, i + 1] * f[:, None]
            if want_heading:
                head[sel] = yaw[rows, i] * (1 - f) + yaw[rows, i + 1] * f
        return pos, head

    def position_heading(self, actors: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Pose of each (actor, time) pair.

        Parameters
        ----------
        actors : (m,) int
            Actor indices.
        t : (m,) float64
            Times, seconds.

        Returns
        -------
        position : (m, 3) float64
            Local origin, world frame, metres (``Track.position``).
        heading : (m,) float64
            Yaw, radians (``Track.heading``).
        """
        return self._eval(np.asarray(actors, np.int64), np.asarray(t, np.float64), True)

    def speed(self, actors: np.ndarray, t: np.ndarray) -> np.ndarray:
        """(m,) float64 planar speed of each (actor, time) pair, m/s (``Track.speed``: central difference over +-dt)."""
        actors, t = np.asarray(actors, np.int64), np.asarray(t, np.float64)
        h = np.array([self._groups[g][1] for g in range(len(self._groups))])[self._group_of[actors]]
        ahead, _ = self._eval(actors, t + h, False)
        behind, _ = self._eval(actors, t - h, False)
        v = (ahead - behind) / (2 * h)[:, None]
        return np.linalg.norm(v[:, :2], axis=1)

    def knot_box(self, t_start: float, t_end: float) -> tuple[np.ndarray, np.ndarray]:
        """Where every actor's local origin can be during ``[t_start, t_end]``.

        Positions are linear between samples, so the box of the positions at both ends and at
        every sample inside bounds the whole path.

        Returns
        -------
        lo, hi : (n, 3) float64
            Corners of each actor's axis-aligned box, world frame, metres.
        """
        lo, hi = np.empty((self.n, 3)), np.empty((self.n, 3))
        for g, (t0, dt, n_samples, xyz, _yaw) in enumerate(self._groups):
            members = np.flatnonzero(self._group_of == g)
            rows = self._row_of[members]
            ends = [self._eval(members, np.full(len(members), t), False)[0] for t in (t_start, t_end)]
            k0 = max(0, int(np.ceil((t_start - t0) / dt)))
            k1 = min(n_samples - 1, int(np.floor((t_end - t0) / dt)))
            inner = xyz[rows, k0:k1 + 1] if k1 >= k0 else np.zeros((len(members), 0, 3))
            pts = np.concatenate([ends[0][:, None], ends[1][:, None], inner], 1)
            lo[members], hi[members] = pts.min(1), pts.max(1)
        return lo, hi
