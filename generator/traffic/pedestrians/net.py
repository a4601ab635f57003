"""The walk network as flat arrays for stepping walkers, and the numbers every walker lives by.

Edges are sampled uniformly (:class:`~generator.traffic.pedestrians.walkways.Walkways`), so the sample
under any arc length is found without a search. Per sample the network also carries the
squared speed from which a walker can still slow down (at :data:`B_MAX`) for every turn ahead
on the same edge without exceeding :data:`A_LAT` sideways.
"""

from __future__ import annotations

import numpy as np

from generator.traffic.pedestrians import zones as wz

A_MAX = 1.0        #: speeding up, m/s^2
B_MAX = 1.5        #: slowing down, m/s^2
A_LAT = 1.5        #: turning (lateral) acceleration, m/s^2
YAW_RATE = 4.0     #: heading change, rad/s
FOLLOW_M = 8.0     #: how far ahead leaders are looked for, metres
HURRY = 1.6        #: a walker on the road speeds up to this many times its pace if the walk phase runs out
PLAN = 1.25        #: a walker steps off the curb if it can cross at this many times its pace
MARGIN_S = 1.0     #: ... with this many seconds to spare (the turn past the far curb, the queue ahead)
COMMIT_M = 6.0     #: a walker decides about the signal within this distance of the curb, metres
RED_WEIGHT = 0.25  #: a crossing that will be red on arrival is chosen this many times as often as another way


class Net:
    """The walk network as flat arrays (edges sampled uniformly, see
    :class:`~generator.traffic.pedestrians.walkways.Walkways`)."""

    def __init__(self, ww, zones: wz.Zones, gap: float):
        paths = ww.paths
        self.E = len(paths)
        self.length = np.array([p.s[-1] for p in paths])
        n = np.array([len(p.s) for p in paths])
        self.base = np.r_[0, np.cumsum(n)[:-1]]
        self.last = n - 1
        self.ds = self.length / self.last
        self.pts = np.concatenate([p.points for p in paths])
        self.head = np.concatenate([np.unwrap(p.headings) for p in paths])
        env = []
        for p in paths:      # squared speed limit that still lets a walker slow down for the turns ahead
            kappa = np.abs(np.gradient(np.unwrap(p.headings), p.s))
            q = np.minimum(A_LAT / np.maximum(kappa, 1e-9), 100.0) + 2 * B_MAX * p.s
            env.append(np.minimum.accumulate(q[::-1])[::-1] - 2 * B_MAX * p.s)
        self.env = np.concatenate(env)
        self.env0 = np.r_[self.env[self.base], np.inf]
        width = max(len(s) for s in ww.succ)
        self.succ = np.full((self.E, width), -1, np.int64)
        for e, s in enumerate(ww.succ):
            self.succ[e, :len(s)] = s
        self.nsucc = np.array([len(s) for s in ww.succ])
        self.nodes = sorted({n for n in ww.node if n is not None})
        self.cw = np.array([self.nodes.index(n) if n is not None else -1 for n in ww.node] + [-1])
        self.stop = np.r_[np.nan_to_num(ww.stop_s, nan=np.inf), np.inf]
        self.road1 = np.nan_to_num(ww.road_s[:, 1], nan=-np.inf)
        self.cross_len = np.nan_to_num(ww.road_s[:, 1] - ww.stop_s, nan=0.0)      # curb stop to off the road
        self.gap = gap
        self.z = zones
        self.n_iv = len(zones.edge)
        self.iv_s0 = np.r_[zones.s0, np.inf]
        self.iv_s1 = np.r_[zones.s1, np.inf]
        self.iv_cl = np.r_[zones.cluster, -1]

    def lookup(self, e: np.ndarray, s: np.ndarray):
        """Flat sample index, interpolation weight for arc length ``s`` on edges ``e``."""
        x = np.clip(s, 0.0, self.length[e]) / self.ds[e]
        k = np.minimum(np.floor(x).astype(np.int64), self.last[e] - 1)
        return self.base[e] + k, x - k
