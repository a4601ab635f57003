"""A walker's gait in the world in time: which of its phase meshes it shows at an instant.

Pure numpy. :class:`Gait` is held by a walking :class:`generator.world.actors.Actor`; the phase at a
time is the distance the actor has walked by then over its stride, so every sensor asking at that time
sees the same limbs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Gait:
    """A walker's gait cycle: which of its phase meshes it shows at a time, from the distance walked.

    The phase at ``t`` is ``distance(t) / stride_m`` (modulo 1), ``distance`` the path length of the
    track's positions (horizontal, linear between samples like the pose), so the feet stay planted and
    every sensor that asks at ``t`` sees the same limbs. Phase mesh ``k`` of ``n`` holds the phase ``k / n``;
    an instant shows the nearest one.

    Attributes
    ----------
    keys : tuple of str
        Keys into :attr:`World.prototypes` of the phase meshes (same faces, limbs moved), phase 0 first.
    stride_m : float
        Metres walked per gait cycle (two steps).
    distance : (T,) float64
        Metres walked at each sample of the actor's track (0 at its first sample).
    lo, hi : (n, 3) float64
        Local bounds of each phase mesh.
    """

    keys: tuple[str, ...]
    stride_m: float
    distance: np.ndarray
    lo: np.ndarray
    hi: np.ndarray

    @staticmethod
    def walked(track) -> np.ndarray:
        """(T,) float64 cumulative horizontal path length of the samples of ``track``
        (:class:`generator.world.actors.Track`), metres."""
        step = np.linalg.norm(np.diff(track.xyz[:, :2], axis=0), axis=1)
        return np.r_[0.0, np.cumsum(step)]

    def index(self, track, t) -> np.ndarray:
        """(k,) int64 phase mesh shown at time(s) ``t`` (seconds) by the actor on ``track`` (its own)."""
        if len(self.distance) == 1:
            d = np.zeros(np.size(t))
        else:
            i, f = track._where(t)
            d = self.distance[i] * (1 - f) + self.distance[i + 1] * f
        n = len(self.keys)
        return np.floor(np.mod(d / self.stride_m, 1.0) * n + 0.5).astype(np.int64) % n
