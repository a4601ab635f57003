"""The ego's drive as a function of time: a route driven at a constant speed.

Position and heading are linear in arc length between the route's samples
(:meth:`generator.world.scene.Path.at`), so the pose is piecewise linear in time with
kinks only where a sample is crossed. :meth:`EgoTrajectory.knot_offsets` lists those
instants inside an interval: recording the pose there lets a reader rebuild the pose of
any instant exactly (linear translation, slerp of rotation between knots).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from generator.world.scene import Path


@dataclass(frozen=True)
class EgoTrajectory:
    """A route driven at ``speed_mps`` from its first sample at t = 0.

    Attributes
    ----------
    path : Path
        The route (lane centres, world frame).
    speed_mps : float
        Constant speed, metres per second.
    """

    path: Path
    speed_mps: float

    def T_world_ego(self, t: np.ndarray | float) -> np.ndarray:
        """Ego poses at time(s) ``t`` (seconds).

        Returns
        -------
        (k, 4, 4) float64
            ``T_world_ego`` per time: ISO 8855 ego frame (x forward, y left, z up).
        """
        pos, hd = self.path.at(np.asarray(t, np.float64) * self.speed_mps)
        out = np.repeat(np.eye(4)[None], len(hd), 0)
        c, s = np.cos(hd), np.sin(hd)
        out[:, 0, 0], out[:, 0, 1], out[:, 1, 0], out[:, 1, 1] = c, -s, s, c
        out[:, :3, 3] = pos
        return out

    def time_at_distance(self, s: float) -> float:
        """The time the ego has driven ``s`` metres, seconds."""
        return s / self.speed_mps

    def distance_at(self, t: float) -> float:
        """Metres driven at time ``t``."""
        return t * self.speed_mps

    def max_frames(self, spacing_m: float) -> int:
        """How many distinct frames ``spacing_m`` apart fit on the route (a loop: one lap)."""
        length = self.path.length()
        return max(1, int(np.floor(length / spacing_m)) + (0 if self.path.closed else 1))

    def knot_offsets(self, t0: float, period_s: float) -> np.ndarray:
        """(k,) float64: 0, the offsets in ``(0, period)`` where a route sample is crossed, ``period``."""
        path, speed = self.path, self.speed_mps
        s0, s1 = t0 * speed, (t0 + period_s) * speed
        knots = np.asarray(path.s, np.float64)
        if path.closed:
            length = path.length()
            knots = np.append(knots, length)
            base = np.floor(s0 / length) * length
            knots = np.concatenate([knots + base, knots + base + length])
        inner = knots[(knots > s0) & (knots < s1)]
        return np.unique(np.r_[0.0, (inner - s0) / speed, period_s])
