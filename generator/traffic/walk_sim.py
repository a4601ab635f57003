"""Stepping walkers along the walk network, all at once (numpy over walkers).

Per walker: edge ``e``, arc length ``s`` of its centre, speed ``v``, heading ``yaw`` and the
next :data:`K_ROUTE` edges of its route (drawn when a branch comes into view). Every step
each walker finds the nearest point it must be able to stop before -- a walker ahead on any
branch within ``FOLLOW_M`` (minus the follow gap), the entry of a conflict interval it
has not been granted (:mod:`generator.traffic.walk_zones`), the curb before a crosswalk it
has not committed to -- and takes the largest speed from which it can still stop there
braking at ``B_MAX``, also slow enough for the turns ahead (lateral acceleration
``A_LAT``) and changing by at most ``A_MAX dt`` / ``B_MAX dt`` (:mod:`generator.traffic.walk_net`).

Conflict clusters are entered with a whole movement granted at once; walkers crossing a
street reserve the cluster at the far curb, so people on the pavement let them off the
road. A walker commits to a crosswalk (and steps off the curb) only when
``signals.may_cross`` gives the walk phase time for the whole crossing at its pace; on the
road it hurries (up to :data:`HURRY` times its pace) if it falls behind.
"""

from __future__ import annotations

import logging

import numpy as np

from generator.traffic import walk_zones as wz
from generator.traffic.walk_net import A_MAX, B_MAX, YAW_RATE, Net

log = logging.getLogger(__name__)

HURRY = 1.5        #: a walker on the road speeds up to this many times its pace if the walk phase runs out
K_ROUTE = 12       #: edges of route known ahead
COMMIT_M = 6.0     #: a walker decides about the signal within this distance of the curb, metres
RESERVE_S = 4.0    #: a walker crossing a street claims the corner ahead this many seconds before it gets there


def simulate(net: Net, signals, e, s, vdes, decide, n_warm: int, n_steps: int, dt: float):
    """Walk ``len(e)`` walkers for ``n_warm`` unrecorded then ``n_steps`` recorded steps.

    Parameters
    ----------
    net : Net
    signals : generator.traffic.signals.Signals
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
    return _Walk(net, signals, e, s, vdes, decide).run(n_warm, n_steps, dt)


class _Walk:
    def __init__(self, net: Net, signals, e, s, vdes, decide):
        self.net, self.sig = net, signals
        n = len(e)
        self.N, self.ar = n, np.arange(n)
        self.e, self.s = np.asarray(e, np.int64).copy(), np.asarray(s, np.float64).copy()
        self.v, self.vdes = np.zeros(n), np.asarray(vdes, np.float64)
        self.decide, self.dptr = decide, np.zeros(n, np.int64)
        self.hop = np.zeros(n, np.int64)
        self.route = np.zeros((n, K_ROUTE), np.int64)
        for k in range(K_ROUTE):
            self.route[:, k] = self._choose(self.route[:, k - 1] if k else self.e, self.ar)
        self.commit = np.full(n, -1, np.int64)
        self.held = np.zeros((n, net.n_iv + 1), bool)
        self.occ = np.zeros(net.n_iv + 1, np.int64)
        self.grants: list[list[tuple[int, float, int]]] = [[] for _ in range(n)]
        self.holding: list[int] = []          # walkers with grants
        self.moves: dict[int, tuple] = {}
        i, f = net.lookup(self.e, self.s)
        self.yaw = net.head[i] * (1 - f) + net.head[i + 1] * f

    def _choose(self, prev: np.ndarray, who: np.ndarray) -> np.ndarray:
        u = self.decide[who, np.minimum(self.dptr[who], self.decide.shape[1] - 1)]
        self.dptr[who] += 1
        return self.net.succ[prev, (u * self.net.nsucc[prev]).astype(np.int64)]

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
    def _ahead(self):
        net, e, s = self.net, self.e, self.s
        rem = net.length[e] - s
        dist = np.empty((self.N, K_ROUTE))          # route distance to the start of route[:, k]
        dist[:, 0] = rem
        dist[:, 1:] = rem[:, None] + np.cumsum(net.length[self.route[:, :-1]], 1)
        return rem, dist

    def _leaders(self, rem):
        net, e, s = self.net, self.e, self.s
        order = np.lexsort((s, e))
        es, ss = e[order], s[order]
        d, who = np.full(self.N, np.inf), np.full(self.N, -1)
        same = es[1:] == es[:-1]
        d[order[:-1][same]], who[order[:-1][same]] = (ss[1:] - ss[:-1])[same], order[1:][same]
        head = np.r_[True, ~same]
        first_s, first_w = np.full(net.E + 1, np.inf), np.full(net.E + 1, -1)
        first_s[es[head]], first_w[es[head]] = ss[head], order[head]
        re = net.reach_e[e]
        cand = rem[:, None] + net.reach_d[e] + first_s[re]
        k = cand.argmin(1)
        dd = cand[self.ar, k]
        better = dd < d
        d[better], who[better] = dd[better], first_w[re[self.ar, k]][better]
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
        rem, dist = self._ahead()
        d_lead, lead = self._leaders(rem)
        d_zone, z_iv = self._zone(dist)
        d_curb, cw = self._curb(dist)
        self._commit(t, d_lead, lead, d_zone, d_curb, cw)
        d_curb, _ = self._curb(dist)
        granted = self._grant(t, dt, dist, d_lead, lead, d_zone, z_iv, d_curb, cw)
        if len(granted):
            d_zone[granted] = self._zone(dist, granted)[0]
        d_stop = np.minimum.reduce([d_lead - net.gap, d_zone - 0.01, d_curb])
        v_safe = -B_MAX * dt + np.sqrt((B_MAX * dt) ** 2 + 2 * B_MAX * np.maximum(d_stop, 0.0))
        i, f = net.lookup(self.e, self.s)
        turn2 = np.minimum(net.env[i], (net.env0[self.route] + 2 * B_MAX * np.maximum(dist - self.v[:, None] * dt, 0)).min(1))
        target = np.minimum(self._pace(t), np.sqrt(np.maximum(turn2, 0.0)))
        lo = np.maximum(self.v - B_MAX * dt, 0.0)
        v = np.minimum(np.clip(target, lo, self.v + A_MAX * dt), v_safe)
        if (v < lo - 1e-9).any():
            log.debug("%d walkers braked harder than %.1f m/s^2 at t=%.2f", int((v < lo - 1e-9).sum()), B_MAX, t)
        self.v = v
        self.s = self.s + v * dt
        self._advance()
        i, f = net.lookup(self.e, self.s)
        h = net.head[i] * (1 - f) + net.head[i + 1] * f
        self.yaw = self.yaw + np.clip(np.angle(np.exp(1j * (h - self.yaw))), -YAW_RATE * dt, YAW_RATE * dt)

    def _pace(self, t: float) -> np.ndarray:
        """Desired speed: the walker's pace, more on the road when the walk phase runs short."""
        net, pace = self.net, self.vdes.copy()
        crossing = np.flatnonzero((self.commit == self.e) & (self.s <= net.road1[self.e] + 0.2))
        for k in crossing:
            left = self.sig.walk_left(net.nodes[net.cw[self.e[k]]], t) - 0.3
            need = (net.road1[self.e[k]] + 0.2 - self.s[k]) / max(left, 0.05)
            pace[k] = min(max(pace[k], need), HURRY * self.vdes[k])
        return pace

    def _commit(self, t, d_lead, lead, d_zone, d_curb, cw) -> None:
        """Commit to the crosswalk ahead when the walk phase leaves time for the whole crossing."""
        ok = (d_curb < COMMIT_M) & (d_zone > d_curb)
        ok &= (d_lead > d_curb) | (self.commit[np.maximum(lead, 0)] == cw)
        for k in np.flatnonzero(ok):
            self._try_commit(k, t, d_curb[k], cw[k])

    def _try_commit(self, k: int, t: float, d_curb: float, cw: int) -> bool:
        net = self.net
        far = d_curb + net.road1[cw] + 0.2 - net.stop[cw]
        need = far / self.vdes[k] + max(self.vdes[k] - self.v[k], 0.0) / A_MAX + 1.0
        if self.sig.may_cross(net.nodes[net.cw[cw]], t, need):
            self.commit[k] = cw
            return True
        return False

    def _movement(self, k: int, iv: int) -> tuple[list[tuple[int, int]], np.ndarray, np.ndarray]:
        """Walker ``k``'s next pass through ``iv``'s cluster: ``(hop, interval)`` pairs in route order
        (contiguous: gaps under :data:`~generator.traffic.walk_zones.ADJACENT_M`), the (m,) intervals
        and the (c,) intervals in conflict with them."""
        net = self.net
        key = (int(self.hop[k]), int(iv))
        if self.moves.get(k, (None,))[0] == key:
            return self.moves[k][1]
        z, hop = net.iv_cl[iv], int(self.hop[k])
        out, start, end = [], -self.s[k], -np.inf       # start: route distance to the start of the edge
        for m, edge in enumerate([self.e[k], *self.route[k]]):
            if out and start - end > wz.ADJACENT_M:
                break
            for j in net.z.by_edge[edge]:
                if net.iv_cl[j] != z or (m == 0 and net.iv_s1[j] <= self.s[k]):
                    continue
                if out and start + net.iv_s0[j] - end > wz.ADJACENT_M:
                    break
                out.append((hop + m, int(j)))
                end = start + net.iv_s1[j]
            start += net.length[edge]
        ivs = np.array([j for _, j in out], np.int64)
        found = (out, ivs, np.concatenate([net.z.conflicts[j] for j in ivs]))
        self.moves[k] = (key, found)
        return found

    def _exit(self, k: int, move, dist) -> float:
        """Route distance from walker ``k`` to the end of its movement, metres."""
        h, j = move[-1]
        back = h - self.hop[k]
        return float(self.net.iv_s1[j] - self.s[k] if back == 0 else dist[k, back - 1] + self.net.iv_s1[j])

    def _grant(self, t, dt, dist, d_lead, lead, d_zone, z_iv, d_curb, cw) -> None:
        net = self.net
        reach = self.v ** 2 / (2 * B_MAX) + 2 * self.v * dt + 0.5
        on_road = (self.commit == self.e) & (self.commit >= 0) & (d_zone < reach + RESERVE_S * self.vdes)
        want = np.isfinite(d_zone) & ((d_zone < reach) | on_road)
        granted: list[int] = []
        if not want.any():
            return np.array(granted, np.int64)
        reserved = np.zeros(net.n_iv + 1, bool)
        for k in np.flatnonzero(want & on_road):
            reserved[self._movement(k, z_iv[k])[1]] = True
        order = np.flatnonzero(want)[np.lexsort((d_zone[want], ~on_road[want]))]
        for k in order:
            move, ivs, clash = self._movement(k, z_iv[k])
            if (self.occ[clash] > self.held[k, clash]).any():
                continue
            if not on_road[k]:
                if d_zone[k] >= reach[k] or reserved[clash].any():
                    continue
                end = self._exit(k, move, dist)
                if d_curb[k] < end and not self._try_commit(k, t, d_curb[k], cw[k]):
                    continue           # it would wait for the signal inside the cluster
                m = lead[k]
                if m >= 0 and d_lead[k] - net.gap < end and (self.v[m] < 0.2 or (
                        cw[m] == cw[k] >= 0 and self.commit[m] != cw[k] and d_curb[k] - net.gap < end)):
                    continue           # it would stand in the cluster behind someone standing or queueing
            self.held[k, ivs] = True
            self.occ[ivs] += 1
            self.grants[k] += [(h, float(net.iv_s1[j]), j) for h, j in move]
            granted.append(k)
            if k not in self.holding:
                self.holding.append(k)
        return np.array(granted, np.int64)

    def _advance(self) -> None:
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
            self.route[over, -1] = self._choose(self.route[over, -2], over)
            self.hop[over] += 1
        for k in self.holding:
            g = self.grants[k]
            while g and (g[0][0] < self.hop[k] or (g[0][0] == self.hop[k] and self.s[k] > g[0][1])):
                _, _, j = g.pop(0)
                self.held[k, j] = False
                self.occ[j] -= 1
        self.holding = [k for k in self.holding if self.grants[k]]
