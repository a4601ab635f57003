"""Stepping walkers along the walk network, all at once (numpy over walkers).

Per walker: edge ``e``, arc length ``s`` of its centre, speed ``v``, heading ``yaw`` and the
next :data:`K_ROUTE` edges of its route (drawn when a branch comes into view). Every step
each walker finds the nearest point it must be able to stop before -- a walker ahead on its
route within ``FOLLOW_M`` (minus the follow gap), the entry of a conflict interval it
has not been granted (:mod:`generator.traffic.walk_zones`), the curb before a crosswalk it
has not committed to -- and takes the largest speed from which it can still stop there
braking at ``B_MAX``, also slow enough for the turns ahead (lateral acceleration
``A_LAT``) and changing by at most ``A_MAX dt`` / ``B_MAX dt`` (:mod:`generator.traffic.walk_net`).

Conflict clusters are entered with a whole movement granted at once. A walker commits to a
crosswalk (and steps off the curb) only when ``signals.may_cross`` gives the walk phase time
for the whole crossing at :data:`PLAN` times its pace (behind whoever crosses ahead of it) and
every cluster up to just past the far curb is granted to it at once, so nobody ever waits on
the road; there it hurries (up to :data:`HURRY` times its pace) if it falls behind.
"""

from __future__ import annotations

import logging

import numpy as np

from generator.traffic import walk_zones as wz
from generator.traffic.signals import CYCLE_S, WALK_S
from generator.traffic.walk_net import A_MAX, B_MAX, FOLLOW_M, YAW_RATE, Net

log = logging.getLogger(__name__)

HURRY = 1.6        #: a walker on the road speeds up to this many times its pace if the walk phase runs out
PLAN = 1.25        #: a walker steps off the curb if it can cross at this many times its pace
MARGIN_S = 1.0     #: ... with this many seconds to spare (the turn past the far curb, the queue ahead)
RED_WEIGHT = 0.25  #: a crossing that will be red on arrival is chosen this many times as often as another way
K_ROUTE = 12       #: edges of route known ahead
COMMIT_M = 6.0     #: a walker decides about the signal within this distance of the curb, metres


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
    return _Walk(net, signals, e, s, vdes, decide, -n_warm * dt).run(n_warm, n_steps, dt)


class _Walk:
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
        for r, c in zip(*np.nonzero(ok & (net.cw[np.maximum(succ, 0)] >= 0) & (net.nsucc[prev] > 1)[:, None])):
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
        turn2 = np.minimum(net.env[i], (net.env0[self.route] + 2 * B_MAX * np.maximum(dist - self.v[:, None] * dt, 0)).min(1))
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

    def _crossing_time(self, k: int, d: float, pace: float) -> float:
        """Seconds for walker ``k`` to walk ``d`` metres at ``pace`` from its speed now (plus a margin)."""
        return d / pace + max(pace - self.v[k], 0.0) ** 2 / (2 * A_MAX * pace) + MARGIN_S

    def _try_commit(self, k: int, t: float, dist, d_curb: float, cw: int, lead: int, d_lead: float,
                    skip=()) -> bool:
        """Commit walker ``k`` to crosswalk edge ``cw`` (its curb ``d_curb`` metres ahead) if whoever is
        ahead of it before the curb has committed there too, the walk phase leaves time to cross --
        after the one ahead has (its promise) -- and every pass through a cluster from the curb to just
        past the far curb (but intervals ``skip``) can be granted now: so nobody ever waits on the road."""
        net = self.net
        if lead >= 0 and d_lead <= d_curb and self.commit[lead] != cw:
            return False
        far = d_curb + net.road1[cw] + 0.2 - net.stop[cw]
        pace = PLAN * self.vdes[k]            # a little brisker than usual; on the road it may hurry more
        need = self._crossing_time(k, far, pace)
        if need > WALK_S - 1.0 or self.waited[k] > CYCLE_S - WALK_S:   # a wide street, or missed a phase
            pace = 0.9 * HURRY * self.vdes[k]
            need = self._crossing_time(k, far, pace)
        if lead >= 0 and self.commit[lead] == cw:      # it cannot leave the road before the one ahead
            v = min(pace, PLAN * self.vdes[lead])       # a platoon walks at its leader's pace
            need = max(need, self.promise[lead] - t + (net.gap + v * v / (2 * B_MAX)) / v + 0.5)
        if not self.sig.may_cross(net.nodes[net.cw[cw]], t, need):
            return False
        moves, seen = [], set(skip)
        for m, edge in enumerate([self.e[k], *self.route[k]]):
            start = -self.s[k] if m == 0 else dist[k, m - 1]
            for j in net.z.by_edge[edge]:
                entry = start + net.iv_s0[j]
                if j < net.n_iv and d_curb < entry < far + 2 * net.gap + 1.0 and j not in seen and not self.held[k, j]:
                    moves.append(self._pass(k, j))
                    seen.update(moves[-1][1].tolist())
        if any((self.occ[clash] > self.held[k, clash]).any() for _, _, clash in moves):
            return False
        for move in moves:
            self._take(k, move)
        self.commit[k], self.promise[k] = cw, t + need
        return True

    def _take(self, k: int, move) -> None:
        """Grant walker ``k`` the intervals of ``move`` (see :meth:`_pass`) it does not hold yet."""
        hops = [(h, j) for h, j in move[0] if not self.held[k, j]]
        ivs = np.array([j for _, j in hops], np.int64)
        self.held[k, ivs] = True
        self.occ[ivs] += 1
        self.grants[k] = sorted(self.grants[k] + [(h, float(self.net.iv_s1[j]), int(j)) for h, j in hops])
        if k not in self.holding:
            self.holding.append(k)

    def _movement(self, k: int, iv: int):
        """:meth:`_pass` through ``iv``'s cluster, remembered while walker ``k`` waits for it."""
        key = (int(self.hop[k]), int(iv))
        if self.moves.get(k, (None,))[0] != key:
            self.moves[k] = (key, self._pass(k, iv))
        return self.moves[k][1]

    def _pass(self, k: int, iv: int) -> tuple[list[tuple[int, int]], np.ndarray, np.ndarray]:
        """Walker ``k``'s pass through ``iv``'s cluster starting at interval ``iv`` (its next
        occurrence on the route): ``(hop, interval)`` pairs in route order (contiguous: gaps under
        :data:`~generator.traffic.walk_zones.ADJACENT_M`), the (m,) intervals and the (c,)
        intervals in conflict with them."""
        net = self.net
        z, hop = net.iv_cl[iv], int(self.hop[k])
        out, start, end = [], -self.s[k], -np.inf       # start: route distance to the start of the edge
        for m, edge in enumerate([self.e[k], *self.route[k]]):
            if out and start - end > wz.ADJACENT_M:
                break
            for j in net.z.by_edge[edge]:
                if not out:
                    if j != iv or (m == 0 and net.iv_s1[j] <= self.s[k]):
                        continue                        # not yet at ``iv``
                elif net.iv_cl[j] != z:
                    continue
                elif start + net.iv_s0[j] - end > wz.ADJACENT_M:
                    break
                out.append((hop + m, int(j)))
                end = start + net.iv_s1[j]
            start += net.length[edge]
        ivs = np.array([j for _, j in out], np.int64)
        return out, ivs, np.concatenate([net.z.conflicts[j] for j in ivs])

    def _exit(self, k: int, move, dist) -> float:
        """Route distance from walker ``k`` to the end of its movement, metres."""
        h, j = move[-1]
        back = h - self.hop[k]
        return float(self.net.iv_s1[j] - self.s[k] if back == 0 else dist[k, back - 1] + self.net.iv_s1[j])

    def _decide(self, t, dt, dist, d_lead, lead, d_zone, z_iv, d_curb, cw) -> np.ndarray:
        """Commit walkers to the crossings ahead and grant the clusters they are about to enter,
        longest waiting first (then nearest); returns who got a cluster."""
        reach = self.v ** 2 / (2 * B_MAX) + 2 * self.v * dt + 0.5
        cross = (d_curb < COMMIT_M) & (d_zone > d_curb)          # nothing to enter before the curb
        enter = np.isfinite(d_zone) & (d_zone < reach)
        want = np.flatnonzero(cross | enter)
        granted = []
        for k in want[np.lexsort((d_zone[want], -self.waited[want]))]:
            if cross[k] and not self._try_commit(k, t, dist, d_curb[k], cw[k], lead[k], d_lead[k]):
                continue
            if enter[k] and self._enter(k, t, dist, d_lead[k], lead, d_curb, cw, z_iv[k]):
                granted.append(k)
        return np.array(granted, np.int64)

    def _enter(self, k: int, t: float, dist, d_lead: float, lead, d_curb, cw, iv: int) -> bool:
        """Grant walker ``k`` its pass through the cluster of interval ``iv`` if no one holds a
        conflicting interval, it will not stand inside behind someone standing or queueing, and --
        when its curb is inside -- it can commit to the crossing at once."""
        net = self.net
        move = self._movement(k, iv)
        hops, _, clash = move
        if (self.occ[clash] > self.held[k, clash]).any():
            return False
        end = self._exit(k, hops, dist)
        m = lead[k]
        if m >= 0 and d_lead - net.gap < end and (self.v[m] < 0.2 or (
                cw[m] == cw[k] >= 0 and self.commit[m] != cw[k] and d_curb[k] - net.gap < end)):
            return False
        if self.commit[k] != cw[k] and d_curb[k] < end and not self._try_commit(
                k, t, dist, d_curb[k], cw[k], m, d_lead, move[1].tolist()):
            return False
        self._take(k, move)
        return True

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
