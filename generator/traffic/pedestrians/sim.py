"""Stepping walkers along the walk network, all at once (numpy over walkers).

Per walker: edge ``e``, arc length ``s`` of its centre, speed ``v``, heading ``yaw`` and the
next :data:`K_ROUTE` edges of its route (drawn when a branch comes into view: at random, a
crossing that will be red on arrival less often). Every step each walker finds the nearest
point it must be able to stop before -- a walker ahead on its route within ``FOLLOW_M``
(minus the follow gap), the entry of a conflict interval it has not been granted, the curb
before a crosswalk it has not committed to (:mod:`generator.traffic.pedestrians.rules`) -- and takes
the largest speed from which it can still stop there braking at ``B_MAX``, slow enough for
the turns ahead (sideways acceleration ``A_LAT``) and changing by at most ``A_MAX dt`` /
``B_MAX dt``; on a crossing it hurries (up to ``HURRY`` times its pace, with everyone behind
it there) if the walk phase runs short. Its heading follows the path at up to ``YAW_RATE``
(limits in :mod:`generator.traffic.pedestrians.net`).
"""

from __future__ import annotations

import logging

import numpy as np

from generator.traffic.lanes.signals import WALK_S
from generator.traffic.pedestrians.net import A_MAX, B_MAX, FOLLOW_M, HURRY, MARGIN_S, PLAN, RED_WEIGHT, YAW_RATE, Net
from generator.traffic.pedestrians.rules import Rules

log = logging.getLogger(__name__)

K_ROUTE = 12       #: edges of route known ahead


def simulate(net: Net, signals, e, s, vdes, decide, n_warm: int, n_steps: int, dt: float):
    """Walk ``len(e)`` walkers for ``n_warm`` unrecorded then ``n_steps`` recorded steps.

    Parameters
    ----------
    net : Net
    signals : generator.traffic.lanes.signals.Signals
    e, s : (N,) int64, float64
        Start edges and arc lengths (clear of each other and of conflict intervals, off the road).
    vdes : (N,) float64
        Walking pace of each walker, m/s.
    decide : (N, D) float64
        Uniform draws in [0, 1), one per branch each walker meets, in order.
    n_warm, n_steps : int
        Steps before t = 0 (not recorded) and recorded steps from t = 0.
    dt : float
        Step, seconds.

    Returns
    -------
    xyz : (N, n_steps, 3) float64
        Positions of the walkers' centres, world frame, metres.
    yaw : (N, n_steps) float64
        Headings, radians, unwrapped.
    """
    return _Walk(net, signals, e, s, vdes, decide, -n_warm * dt).run(n_warm, n_steps, dt)


class _Walk(Rules):
    """The walkers' state and one step of it (the crossing and cluster rules are :class:`Rules`)."""

    def __init__(self, net: Net, signals, e, s, vdes, decide, t0: float):
        self.net, self.sig = net, signals
        n = len(e)
        self.N, self.ar = n, np.arange(n)
        self.e, self.s = np.asarray(e, np.int64).copy(), np.asarray(s, np.float64).copy()
        self.v, self.vdes = np.zeros(n), np.asarray(vdes, np.float64)
        self.decide, self.dptr = decide, np.zeros(n, np.int64)
        self.hop = np.zeros(n, np.int64)
        self.route = np.zeros((n, K_ROUTE), np.int64)
        ahead = net.length[self.e] - self.s                  # route distance to the end of the last edge chosen
        for k in range(K_ROUTE):
            self.route[:, k] = self._choose(self.route[:, k - 1] if k else self.e, self.ar, t0, ahead / self.vdes)
            ahead = ahead + net.length[self.route[:, k]]
        self.commit = np.full(n, -1, np.int64)      # crosswalk edge a walker has committed to
        self.promise = np.zeros(n)                   # ... and when it will be off the road by then, s
        self.waited = np.zeros(n)                    # seconds standing since it last walked
        self.held = np.zeros((n, net.n_iv + 1), bool)
        self.occ = np.zeros(net.n_iv + 1, np.int64)
        self.grants: list[list[tuple[int, float, int]]] = [[] for _ in range(n)]
        self.holding: list[int] = []          # walkers with grants
        self.moves: dict[int, tuple] = {}
        i, f = net.lookup(self.e, self.s)
        self.yaw = net.head[i] * (1 - f) + net.head[i + 1] * f

    def _choose(self, prev: np.ndarray, who: np.ndarray, t: float, eta: np.ndarray) -> np.ndarray:
        """Next edge after ``prev`` for walkers ``who`` (reaching its end in ``eta`` seconds from ``t``):
        at random over the successors, a crossing whose signal will not let the walker across when
        it gets there :data:`RED_WEIGHT` times as likely as another way; crossings a walker could not
        make within a walk phase even hurrying are left out."""
        net = self.net
        u = self.decide[who, np.minimum(self.dptr[who], self.decide.shape[1] - 1)]
        self.dptr[who] += 1
        succ = net.succ[prev]                                              # (n, S), -1 padded
        length = np.where(succ >= 0, net.cross_len[succ], np.inf)
        ok = (succ >= 0) & (length / (0.9 * HURRY * self.vdes[who, None]) + MARGIN_S < WALK_S - 1.0)
        ok = np.where(ok.any(1, keepdims=True), ok, succ >= 0)
        weight = ok.astype(np.float64)
        for r, c in zip(*np.nonzero(ok & (net.cw[np.maximum(succ, 0)] >= 0) & (net.nsucc[prev] > 1)[:, None]),
                        strict=True):
            need = length[r, c] / (PLAN * self.vdes[who[r]]) + MARGIN_S
            if not self.sig.may_cross(net.nodes[net.cw[succ[r, c]]], t + eta[r], need):
                weight[r, c] = RED_WEIGHT
        cum = np.cumsum(weight, 1)
        col = (cum > (u * cum[:, -1])[:, None]).argmax(1)
        return succ[np.arange(len(who)), col]

    def run(self, n_warm: int, n_steps: int, dt: float):
        xyz, yaw = np.zeros((self.N, n_steps, 3)), np.zeros((self.N, n_steps))
        for k in range(n_warm + n_steps):
            self._step((k - n_warm) * dt, dt)
            if k >= n_warm:
                i, f = self.net.lookup(self.e, self.s)
                xyz[:, k - n_warm] = self.net.pts[i] * (1 - f[:, None]) + self.net.pts[i + 1] * f[:, None]
                yaw[:, k - n_warm] = self.yaw
        return xyz, yaw

    # -- what lies ahead -----------------------------------------------------------------
    def _ahead(self) -> np.ndarray:
        """(N, K_ROUTE) route distance from each walker to the start of each edge of its route, metres."""
        net, e, s = self.net, self.e, self.s
        rem = net.length[e] - s
        dist = np.empty((self.N, K_ROUTE))          # route distance to the start of route[:, k]
        dist[:, 0] = rem
        dist[:, 1:] = rem[:, None] + np.cumsum(net.length[self.route[:, :-1]], 1)
        return dist

    def _leaders(self, dist):
        """Route distance to the nearest walker ahead on each walker's own route (centre to centre), and who."""
        net, e, s = self.net, self.e, self.s
        order = np.lexsort((s, e))
        es, ss = e[order], s[order]
        d, who = np.full(self.N, np.inf), np.full(self.N, -1)
        same = es[1:] == es[:-1]
        d[order[:-1][same]], who[order[:-1][same]] = (ss[1:] - ss[:-1])[same], order[1:][same]
        head = np.r_[True, ~same]
        first_s, first_w = np.full(net.E, np.inf), np.full(net.E, -1)
        first_s[es[head]], first_w[es[head]] = ss[head], order[head]
        cand = np.where(dist < FOLLOW_M, dist + first_s[self.route], np.inf)
        k = cand.argmin(1)
        dd = cand[self.ar, k]
        better = dd < d
        d[better], who[better] = dd[better], first_w[self.route[self.ar, k]][better]
        return d, who

    def _zone(self, dist, who=None):
        """Distance to the entry of the next interval not granted, and that interval (for walkers ``who``)."""
        net = self.net
        who = self.ar if who is None else who
        e, s, held, ar = self.e[who], self.s[who], self.held[who], np.arange(len(who))
        iv = net.z.by_edge[e]
        cur = np.where((net.iv_s0[iv] > s[:, None]) & ~held[ar[:, None], iv], net.iv_s0[iv] - s[:, None], np.inf)
        ivr = net.z.by_edge[self.route[who]].reshape(len(who), -1)                 # (n, K * M)
        start = np.repeat(dist[who], net.z.by_edge.shape[1], axis=1)
        ahead = np.where(~held[ar[:, None], ivr], start + net.iv_s0[ivr], np.inf)
        both = np.concatenate([cur, ahead], 1)
        k = both.argmin(1)
        return both[ar, k], np.concatenate([iv, ivr], 1)[ar, k]

    def _curb(self, dist):
        """Distance to the next curb stop not committed to, and its crosswalk edge (-1: none)."""
        net, e, s = self.net, self.e, self.s
        here = (net.cw[e] >= 0) & (s < net.stop[e] + 0.5)    # (a walker at its stop stays there)
        on = net.cw[self.route] >= 0
        k = on.argmax(1)
        cw = np.where(here, e, np.where(on.any(1), self.route[self.ar, k], -1))
        d = np.where(here, net.stop[e] - s, dist[self.ar, k] + net.stop[cw]) - 0.01
        d = np.where((cw < 0) | (self.commit == cw), np.inf, d)
        return d, cw

    # -- one step --------------------------------------------------------------------------
    def _step(self, t: float, dt: float) -> None:
        net = self.net
        dist = self._ahead()
        d_lead, lead = self._leaders(dist)
        d_zone, z_iv = self._zone(dist)
        d_curb, cw = self._curb(dist)
        granted = self._decide(t, dt, dist, d_lead, lead, d_zone, z_iv, d_curb, cw)
        if len(granted):
            d_zone[granted] = self._zone(dist, granted)[0]
        d_curb, _ = self._curb(dist)
        d_stop = np.minimum.reduce([d_lead - net.gap, d_zone - 0.01, d_curb])
        v_safe = -B_MAX * dt + np.sqrt((B_MAX * dt) ** 2 + 2 * B_MAX * np.maximum(d_stop, 0.0))
        i, f = net.lookup(self.e, self.s)
        reach = net.env0[self.route] + 2 * B_MAX * np.maximum(dist - self.v[:, None] * dt, 0)
        turn2 = np.minimum(net.env[i], reach.min(1))
        target = np.minimum(self._pace(t, dist), np.sqrt(np.maximum(turn2, 0.0)))
        lo = np.maximum(self.v - B_MAX * dt, 0.0)
        v = np.minimum(np.clip(target, lo, self.v + A_MAX * dt), v_safe)
        if (v < lo - 1e-9).any():
            log.debug("%d walkers braked harder than %.1f m/s^2 at t=%.2f", int((v < lo - 1e-9).sum()), B_MAX, t)
        self.v = v
        self.waited = np.where(v < 0.1, self.waited + dt, 0.0)
        self.s = self.s + v * dt
        self._advance(t)
        i, f = net.lookup(self.e, self.s)
        h = net.head[i] * (1 - f) + net.head[i + 1] * f
        self.yaw = self.yaw + np.clip(np.angle(np.exp(1j * (h - self.yaw))), -YAW_RATE * dt, YAW_RATE * dt)

    def _pace(self, t: float, dist) -> np.ndarray:
        """Desired speed: the walker's pace; on a crossing at least the pace that gets everyone
        committed behind it there off the road before the walk phase ends (a platoon moves together)."""
        net, pace = self.net, self.vdes.copy()
        who = np.flatnonzero(self.commit >= 0)
        if not len(who):
            return pace
        cw = self.commit[who]
        on = self.route[who] == cw[:, None]
        pos = np.where(self.e[who] == cw, self.s[who], -dist[who, on.argmax(1)])   # along the crosswalk edge
        keep = pos <= net.road1[cw] + 0.2
        who, cw, pos = who[keep], cw[keep], pos[keep]
        if not len(who):
            return pace
        left = np.array([self.sig.walk_left(net.nodes[net.cw[c]], t) for c in cw]) - 0.3
        need = (net.road1[cw] + 0.2 - pos) / np.maximum(left, 0.05)
        order = np.lexsort((pos, cw))                       # per crossing, from the back to the front
        _, group = np.unique(cw[order], return_inverse=True)
        big = need.max() + 1.0
        behind = np.maximum.accumulate(need[order] + group * big) - group * big
        k = who[order]
        pace[k] = np.minimum(np.maximum(pace[k], behind), HURRY * self.vdes[k])
        return pace

    def _advance(self, t: float) -> None:
        """Move walkers past the ends of their edges onto the next route edge; release passed intervals."""
        net = self.net
        while True:
            over = np.flatnonzero(self.s >= net.length[self.e])
            if not len(over):
                break
            self.s[over] -= net.length[self.e[over]]
            left = self.e[over]
            self.commit[over] = np.where(self.commit[over] == left, -1, self.commit[over])
            self.e[over] = self.route[over, 0]
            self.route[over, :-1] = self.route[over, 1:]
            ahead = net.length[self.e[over]] - self.s[over] + net.length[self.route[over, :-1]].sum(1)
            self.route[over, -1] = self._choose(self.route[over, -2], over, t, ahead / self.vdes[over])
            self.hop[over] += 1
        for k in self.holding:
            g = self.grants[k]
            while g and (g[0][0] < self.hop[k] or (g[0][0] == self.hop[k] and self.s[k] > g[0][1])):
                _, _, j = g.pop(0)
                self.held[k, j] = False
                self.occ[j] -= 1
        self.holding = [k for k in self.holding if self.grants[k]]
