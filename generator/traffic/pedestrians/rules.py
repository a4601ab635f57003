"""The rules for crossing streets and passing conflict clusters (a mixin of
:class:`~generator.traffic.pedestrians.sim._Walk`).

A walker enters a conflict cluster (:mod:`generator.traffic.pedestrians.zones`) only with its whole
pass through it granted, so no two walkers ever stand in conflicting intervals, and not if it
would then stand inside behind someone standing or queueing. It commits to a crosswalk (and
steps off the curb) only when ``signals.may_cross`` leaves time for the whole crossing at
``PLAN`` times its pace -- behind whoever crosses ahead of it, whose promise it chains onto --
and every pass through a cluster up to just past the far curb is granted to it at once: so
nobody ever waits on the road. Decisions go longest-waiting first.
"""

from __future__ import annotations

import numpy as np

from generator.traffic.lanes.signals import CYCLE_S, WALK_S
from generator.traffic.pedestrians import zones as wz
from generator.traffic.pedestrians.net import A_MAX, B_MAX, COMMIT_M, HURRY, MARGIN_S, PLAN


class Rules:
    """Commit and grant decisions on the state of :class:`~generator.traffic.pedestrians.sim._Walk`."""

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
        :data:`~generator.traffic.pedestrians.zones.ADJACENT_M`), the (m,) intervals and the (c,)
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
