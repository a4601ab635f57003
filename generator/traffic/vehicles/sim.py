"""Vehicles on the lane graph: car-following, signalised intersections, turns; the ego among them.

Kinematic, not physical. Every vehicle is a point ``s`` (its box centre) moving along its
planned edges of the :class:`~generator.traffic.lanes.graph.LaneGraph`, with

* **car-following** by the Intelligent Driver Model (IDM: desired speed, safe time gap
  ``T``, minimum gap ``s0``, comfortable braking ``b``) against the nearest vehicle ahead on
  its plan (a vehicle whose rear still hangs over the previous edge counts there too);
* **turn speeds**: at most ``sqrt(a_lat r)`` on an arc, approached at comfortable braking; the
  same for an edge's speed limit (shared streets, :mod:`generator.traffic.lanes.speed_caps`);
* **intersections**: a vehicle stops with its front at the stop line until it is *granted*
  its connector: the node's signal lets vehicles in (:mod:`generator.traffic.lanes.signals`), no
  vehicle holds a conflicting connector (:func:`generator.traffic.lanes.conflicts`; a bus or
  truck longer than 6 m holds the whole node), the exit lane has room for it to clear the
  far crosswalk, and no pedestrian is on or about to step onto a crosswalk its box passes over
  (:mod:`generator.traffic.lanes.crosswalks`). It
  holds the grant until its rear is past the far crosswalk. Vehicles wait clear of where a long
  vehicle turning through the node (or on a roundabout's ring) swings over their stop or give-way
  line, and it is granted only while nobody sits there (:mod:`generator.traffic.lanes.turn_clearance`);
* **the ego** is one of them: it drives route 0's walk on the graph at ``paths.speed_mps``,
  and at an intersection comes to a full stop for 1-3 s with ``traffic.ego_stop_probability``.

Accelerations are clamped to ``[-B_MAX, a_max]``; speeds never go negative.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field

import numpy as np

from generator.layout.network.measures import ARM_DIRS
from generator.traffic.lanes.crosswalks import swept_arms
from generator.traffic.lanes.graph import LaneGraph
from generator.traffic.lanes.roundabouts import GIVE_WAY_CLEAR_S, GIVE_WAY_REQUEST_M
from generator.traffic.lanes.signals import CLEAR_S
from generator.traffic.lanes.speed_caps import speed_caps
from generator.traffic.lanes.turn_clearance import held_setback, is_large, waiting_clear

log = logging.getLogger(__name__)

S0_M = 2.0          #: IDM minimum gap
T_GAP_S = 1.2       #: IDM safe time gap
B_COMF = 2.5        #: comfortable braking, m/s^2
B_MAX = 8.0         #: hardest braking ever applied, m/s^2
A_LAT = 2.0         #: lateral acceleration on arcs, m/s^2
LOOKAHEAD_M = 80.0
REQUEST_M = 30.0    #: a vehicle asks for its connector this close to the stop line
BIG_M = 6.0         #: longer vehicles hold the whole node


@dataclass
class Vehicle:
    """Simulation state of one vehicle (``s`` and ``v`` change every step)."""

    index: int
    length: float
    width: float
    v_des: float
    a_max: float
    plan: list[int]
    s: float
    rng: np.random.Generator
    v: float = 0.0
    prev: int | None = None
    grant: int | None = None          #: connector edge held
    ego_route: list[int] | None = None
    route_pos: int = 0
    stop_p: float = 0.0
    dwell_until: float | None = None
    decided: dict = field(default_factory=dict)
    avoid: frozenset = frozenset()    #: lanes too narrow, turns too tight for it (lane_clearance.too_narrow)

    @property
    def edge(self) -> int:
        return self.plan[0]


class VehicleSim:
    """Steps every vehicle by ``dt`` seconds (see the module docstring).

    Parameters
    ----------
    graph : LaneGraph
    signals : generator.traffic.lanes.signals.Signals
    vehicles : list of Vehicle
        Their plans start with the edge they stand on.
    crossing : callable or None
        ``crossing(node, arm, t0, t1) -> bool``: is a pedestrian on the crosswalk of ``arm``
        at ``node`` at any time in ``[t0, t1]``.
    """

    def __init__(self, graph: LaneGraph, signals, vehicles: list[Vehicle], crossing=None):
        self.g, self.signals, self.vehicles, self.crossing = graph, signals, vehicles, crossing
        self.holders: dict = {}   # node -> {vehicle index: connector edge}
        self.caps = speed_caps(graph)   # edge -> speed limit (shared streets), m/s
        self.occ: dict = {}             # this step's occupancy (edge -> [(s, vehicle)]), for turn_clearance
        # asked for every vehicle at every step: the lane graph does not change during a run
        self.length = [e.length for e in graph.edges]                  # metres
        self.radius = [graph.turn_radius(e) for e in graph.edges]      # metres, None: no arc

    # -- plans ---------------------------------------------------------------------------------
    def _extend(self, veh: Vehicle) -> None:
        while len(veh.plan) < 3:
            last = self.g.edges[veh.plan[-1]]
            if veh.ego_route is not None:
                veh.route_pos = (veh.route_pos + 1) % len(veh.ego_route)
                veh.plan.append(veh.ego_route[veh.route_pos])
                continue
            options = last.succ
            if veh.avoid and last.kind == "lane":    # keep out of lanes and turns too tight for it, where it can
                options = [c for c in options
                           if c not in veh.avoid and self.g.edges[c].succ[0] not in veh.avoid] or options
            if last.kind == "lane" and len(options) > 1:  # straight on twice as often as each turn
                w = np.array([0.5 if self.g.edges[c].arms[0] == (self.g.edges[c].arms[1] + 2) % 4 else 0.25
                              for c in options])
                veh.plan.append(options[int(veh.rng.choice(len(options), p=w / w.sum()))])
            elif options:
                veh.plan.append(options[0])
            else:
                return

    # -- one step -------------------------------------------------------------------------------
    def step(self, t: float, dt: float) -> None:
        occ = self.occ = self._occupancy()
        # the stop gap a vehicle's grant check measured is its stop gap for the IDM below too: the grants
        # given meanwhile change no other vehicle's (turn_clearance reads the node users once a step), and
        # a vehicle granted now is asked again (its gap is then unbounded)
        stops = [self._maybe_grant(veh, t, occ) for veh in self.vehicles]
        acc = [self._accel(veh, t, occ, stop) for veh, stop in zip(self.vehicles, stops, strict=True)]
        for veh, a in zip(self.vehicles, acc, strict=True):
            v1 = max(0.0, veh.v + a * dt)
            veh.s += 0.5 * (veh.v + v1) * dt
            veh.v = v1
            self._advance(veh)

    def _occupancy(self) -> dict:
        occ: dict[int, list] = {}
        for veh in self.vehicles:
            occ.setdefault(veh.edge, []).append((veh.s, veh))
            if veh.prev is not None and veh.s < veh.length / 2:
                occ.setdefault(veh.prev, []).append((self.length[veh.prev] + veh.s, veh))
        return occ

    def _leader_gap(self, veh: Vehicle, occ: dict) -> tuple[float, float]:
        """(gap in metres, leader speed) to the nearest vehicle ahead on the plan (inf if none)."""
        offset = 0.0
        for n, e in enumerate(veh.plan):
            best = None
            for s, other in occ.get(e, ()):
                if other is veh:
                    continue
                d = offset + s - (veh.s if n == 0 else 0.0)
                gap = d - (veh.length + other.length) / 2
                if (n > 0 or s > veh.s) and (best is None or gap < best[0]):
                    best = (gap, other.v)
            if best is not None:
                return best
            offset += self.length[e] - (veh.s if n == 0 else 0.0)
            if offset > LOOKAHEAD_M:
                break
        return np.inf, 0.0

    def _stop_gap(self, veh: Vehicle) -> float:
        """Metres from the front to the stop line where the vehicle must wait (inf if it may go on)."""
        edge = self.g.edges[veh.edge]
        if len(veh.plan) < 2:   # nowhere to go on (cannot happen on a pruned graph): wait at the end
            return edge.length - (veh.s + veh.length / 2)
        if edge.kind != "lane" or veh.grant == veh.plan[1]:
            return np.inf
        # short of where a large vehicle turning through the node swings over the line (turn_clearance)
        return edge.length - self.g.stop_s_from_end - (veh.s + veh.length / 2) - held_setback(self, veh)

    def _accel(self, veh: Vehicle, t: float, occ: dict, stop: float | None) -> float:
        """IDM acceleration of ``veh`` now, m/s^2; ``stop``: its :meth:`_stop_gap` from this step's
        :meth:`_maybe_grant`, None where that did not measure it (it is measured again, as it is for a vehicle
        granted in this step)."""
        v0 = self._desired(veh)
        gap, v_lead = self._leader_gap(veh, occ)
        if stop is None or veh.grant == veh.plan[1]:
            stop = self._stop_gap(veh)
        if stop + S0_M < gap:
            gap, v_lead = stop + S0_M, 0.0
        a = veh.a_max * (1.0 - (veh.v / max(v0, 0.1)) ** 4)
        if math.isfinite(gap):
            s_star = S0_M + max(0.0, veh.v * T_GAP_S + veh.v * (veh.v - v_lead) / (2 * math.sqrt(veh.a_max * B_COMF)))
            a -= veh.a_max * (s_star / max(gap, 0.05)) ** 2
        return float(min(max(a, -B_MAX), veh.a_max))   # np.clip's value, without its per-call cost

    def _desired(self, veh: Vehicle) -> float:
        """Desired speed now: the vehicle's own, capped by the arcs ahead (reachable at comfortable braking)."""
        v0 = veh.v_des
        ahead = -veh.s
        for e in veh.plan[:3]:
            r = self.radius[e]
            if r is not None:
                v_turn = math.sqrt(A_LAT * r)
                v0 = min(v0, math.sqrt(v_turn ** 2 + 2 * B_COMF * max(0.0, ahead - veh.length / 2)))
            if e in self.caps:   # a shared street's limit, reached at comfortable braking with the front
                v0 = min(v0, math.sqrt(self.caps[e] ** 2 + 2 * B_COMF * max(0.0, ahead - veh.length / 2)))
            ahead += self.length[e]
        return v0

    # -- intersections ----------------------------------------------------------------------------
    def _maybe_grant(self, veh: Vehicle, t: float, occ: dict) -> float | None:
        """Grant ``veh`` the connector ahead if it may go now; its :meth:`_stop_gap` before this, if asked."""
        edge = self.g.edges[veh.edge]
        if edge.kind != "lane" or len(veh.plan) < 2 or veh.grant == veh.plan[1]:
            return None
        stop = self._stop_gap(veh)
        if stop > REQUEST_M or not self._first_in_line(veh, occ):
            return stop
        conn = self.g.edges[veh.plan[1]]
        node = conn.node
        if veh.ego_route is not None and not self._ego_dwell(veh, t, stop, node):
            return stop
        give_way = self.g.grid.is_roundabout(node)     # no signals: asks late, looks further ahead for people
        if (give_way and stop > GIVE_WAY_REQUEST_M) or not self.signals.vehicles_may_enter(node, t):
            return stop
        key = conflict_key(self.g, conn)
        big = veh.length > BIG_M
        for vid, c in self.holders.get(node, {}).items():
            other = self.g.edges[c]
            okey = conflict_key(self.g, other)
            if c == conn.index and not big and self.vehicles[vid].length <= BIG_M:
                continue
            if big or self.vehicles[vid].length > BIG_M or okey in self.g.conflicts_at(node)[key]:
                return stop
        if not self._room(veh, conn, occ) or ((give_way or is_large(veh))
                                              and not waiting_clear(self, veh, conn, occ, B_COMF)):
            return stop
        # the signals keep vehicles from entering CLEAR_S before a walk phase: only people on (or
        # stepping onto) the crosswalks within that time can meet this vehicle -- on every crosswalk
        # its box passes over, not only those it enters and leaves by (a bus swings its overhangs
        # over the crosswalks of the arms a roundabout's ring passes: lanes.crosswalks)
        window = GIVE_WAY_CLEAR_S if give_way else CLEAR_S
        if self.crossing is not None and any(self.crossing(node, arm, t, t + window)
                                             for arm in swept_arms(self.g, conn, (veh.length, veh.width))):
            return stop
        veh.grant = conn.index
        self.holders.setdefault(node, {})[veh.index] = conn.index
        return stop

    def _first_in_line(self, veh: Vehicle, occ: dict) -> bool:
        """No vehicle between ``veh`` and the stop line except ones already granted through this node."""
        for s, other in occ.get(veh.edge, ()):
            if other is not veh and s > veh.s and other.edge == veh.edge and other.grant is None:
                return False
        return True

    def _room(self, veh: Vehicle, conn, occ: dict) -> bool:
        exit_lane = conn.succ[0]
        release = self.g.stop_s_from_end
        need = release + veh.length + S0_M + 1.0
        for vid, c in self.holders.get(conn.node, {}).items():
            if self.g.edges[c].succ[0] == exit_lane:
                need += self.vehicles[vid].length + S0_M + 1.0
        rears = [s - other.length / 2 for s, other in occ.get(exit_lane, ()) if other.edge == exit_lane]
        room = min(rears) if rears else self.g.edges[exit_lane].length
        return room >= need

    def _ego_dwell(self, veh: Vehicle, t: float, stop: float, node) -> bool:
        """The ego's voluntary full stops: False while it still has to stop or wait at the line."""
        visit = (node, veh.route_pos)
        if visit not in veh.decided:
            veh.decided = {visit: bool(veh.rng.random() < veh.stop_p)}
        if not veh.decided[visit]:
            return True
        if veh.dwell_until is None:
            if veh.v < 0.05 and stop < 1.0:
                veh.dwell_until = t + float(veh.rng.uniform(1.0, 3.0))
            return False
        return not t < veh.dwell_until

    def _advance(self, veh: Vehicle) -> None:
        while veh.s > self.g.edges[veh.edge].length and len(veh.plan) > 1:
            veh.s -= self.g.edges[veh.edge].length
            veh.prev = veh.plan.pop(0)
            if self.g.edges[veh.prev].kind == "lane":
                veh.dwell_until = None
            self._extend(veh)
        if veh.grant is not None and veh.prev == veh.grant and veh.s - veh.length / 2 >= self.g.stop_s_from_end:
            node = self.g.edges[veh.grant].node
            self.holders.get(node, {}).pop(veh.index, None)
            veh.grant = None

    # -- geometry -------------------------------------------------------------------------------
    def pose(self, veh: Vehicle) -> tuple[np.ndarray, float]:
        """((2,) xy of the box centre, heading) of ``veh`` now."""
        p, h = self.g.edges[veh.edge].path.at(veh.s)
        return p[0, :2], float(h[0])


def recorded_poses(graph: LaneGraph, at: list) -> tuple[np.ndarray, np.ndarray]:
    """(steps, vehicles, 2) box-centre xy and (steps, vehicles) headings of the vehicles at the recorded
    ``at[step][vehicle] = (edge, s)``: each edge's arc lengths in one :meth:`Path.at` (the arithmetic of
    :meth:`VehicleSim.pose`, element by element)."""
    edges = np.array([[e for e, _ in row] for row in at], np.int64)
    s = np.array([[s for _, s in row] for row in at], np.float64)
    xy, hd = np.empty(edges.shape + (2,)), np.empty(edges.shape)
    for e in np.unique(edges):
        where = edges == e
        p, h = graph.edges[int(e)].path.at(s[where])
        xy[where], hd[where] = p[:, :2], h
    return xy, hd


def conflict_key(graph: LaneGraph, conn) -> tuple:
    """The conflict-table key of connector ``conn``: ``(arm_in, arm_out, lane)``, or the key
    :mod:`generator.traffic.lanes.one_way` gave it (slots that differ in and out)."""
    return getattr(graph, "conflict_keys", {}).get(conn.index, (*conn.arms, conn.lane))


def arm_towards(node, nb) -> int:
    """Arm index of ``node`` that points to the adjacent node ``nb``."""
    d = np.sign(np.subtract(nb, node))
    return int(np.argmax(ARM_DIRS @ d))
