"""Where vehicles wait at a roundabout's give-way lines while a long or wide vehicle drives the ring.

A 12 m bus (or any box much wider than a car) cannot follow a compact ring the way a car does:
its box centre keeps to the car's path, so its front overhang swings outwards on the exit fillet
and crosses the give-way line of the arm it leaves by (and a wide box reaches over the lines of
arms it passes). Real drivers see this coming: whoever arrives at a give-way line while a bus is
turning out over it holds back short of the line until the bus has gone, and a bus driver does
not pull onto the ring while a vehicle sits at the give-way line it would swing over. The
simulator (:class:`generator.traffic.vehicles.VehicleSim`) does both, from one table computed
here: the *setback* of every approach lane, the distance its vehicles must keep their front back
from the give-way line so that a box waiting there stays clear of a vehicle of a given size on a
given ring connector. Vehicles hang back for a large vehicle on the ring and for one about to take
its connector (so two buses at each other's exit arms do not each wait for the other). This is
chosen over moving the give-way line back for everyone: the painted line is laid out for cars
(which need no setback), and only the rare long vehicle should cost the others room.

Setbacks are measured at a roundabout centred on the origin (every roundabout of a town has the
same cross-section), on the connector's own samples: the holder's box (with
:data:`SETBACK_PAD_M` all round) swept along the ring connector against a waiting box of the
waiting vehicle's width whose front is on the line. The holder's own approach lane is left out
(a follower there is kept behind it by car-following). For a standard car every setback is 0, so
towns whose roundabouts see only cars drive exactly as before.
"""

from __future__ import annotations

import functools

import numpy as np

from generator.layout.roundabouts import ARM_DIRS, ring_path
from generator.traffic.lanes import CAR_BOX_M

SETBACK_PAD_M = 0.3   #: clearance kept between a waiting box and a box on the ring, metres
STOP_TOL_M = 0.2   #: a vehicle stopped this little past its setback still counts as clear (inside the pad)
ABOUT_TO_ENTER_M = 10.0  #: a vehicle this close to its give-way line counts as about to take its connector


def approach_arm(graph, lane) -> int:
    """The arm of ``lane.node`` (a node it arrives at) that the lane edge ``lane`` comes in by."""
    d = lane.path.points[-1, :2] - graph.grid.node_xy(lane.node)
    return int(np.argmax(ARM_DIRS @ d))


@functools.lru_cache(maxsize=256)
def _setbacks(ring, stop_m: float, lanes: int, key: tuple, size: tuple, wait_w: float) -> dict:
    x, y, k = key
    p = ring_path(ring, np.zeros(2), x, y, k)
    hl, hw = size[0] / 2 + SETBACK_PAD_M, size[1] / 2 + SETBACK_PAD_M
    c, s = np.cos(p.headings)[:, None], np.sin(p.headings)[:, None]
    dl, dw = np.array([hl, hl, -hl, -hl]), np.array([hw, -hw, -hw, hw])
    corners = p.points[:, None, :2] + np.stack([c * dl - s * dw, s * dl + c * dw], -1)      # (n, 4, 2)
    n = int(np.ceil(2 * max(hl, hw) / 0.1)) + 1                                             # edges every <= 0.1 m
    pts = (corners[:, :, None] + (np.roll(corners, -1, 1) - corners)[:, :, None]
           * np.linspace(0.0, 1.0, n)[None, None, :, None]).reshape(-1, 2)
    out = {}
    for z in range(4):
        a = -ARM_DIRS[z]                           # direction of travel towards the node
        right = np.array([a[1], -a[0]])
        u = pts @ ARM_DIRS[z]                      # distance out along the arm
        for k2 in range(lanes):
            if (z, k2) == (x, k):
                continue
            v = pts @ right - (k2 + 0.5) * ring.lane_w
            near = np.abs(v) < wait_w / 2
            d = float(u[near].max() - stop_m) if near.any() else -np.inf
            if d > 0:
                out[(z, k2)] = round(d, 3)
    return out


def setbacks(graph, key: tuple, size: tuple[float, float], wait_w: float) -> dict:
    """Setbacks of the approach lanes of a roundabout while a vehicle of ``size`` holds ring connector ``key``.

    Parameters
    ----------
    graph : generator.traffic.lanes.LaneGraph
    key : (int, int, int)
        ``(arm_in, arm_out, lane)`` of the ring connector held.
    size : (float, float)
        Length and width of the holder's box, metres.
    wait_w : float
        Width of the waiting vehicle's box, metres.

    Returns
    -------
    dict
        ``(arm, lane) -> metres`` (> 0) the front of a vehicle waiting on that approach lane must
        keep back from the give-way line; lanes not listed need none.
    """
    memo = graph.__dict__.setdefault("_setback_memo", {})   # asked every step: skip the rounding
    got = memo.get((key, size[0], size[1], wait_w))
    if got is None:
        got = memo[(key, size[0], size[1], wait_w)] = _setbacks(
            graph.grid.ring, round(float(graph.stop_m), 3), graph.grid.lanes, tuple(int(i) for i in key),
            (round(float(size[0]), 2), round(float(size[1]), 2)), round(float(wait_w), 2))
    return got


def _key(graph, conn) -> tuple:
    return getattr(graph, "conflict_keys", {}).get(conn.index, (*conn.arms, conn.lane))


def _approaches(graph, node) -> list:
    """``[(lane edge, arm)]`` of the lane edges arriving at roundabout ``node`` (cached on the graph)."""
    table = graph.__dict__.setdefault("_ring_approaches", {})
    if not table:
        for e in graph.lanes():
            if graph.grid.is_roundabout(e.node):
                table.setdefault(e.node, []).append((e, approach_arm(graph, e)))
    return table.get(node, [])


def held_setback(sim, veh) -> float:
    """Metres ``veh`` must now stop short of its give-way line: the largest setback of its approach
    lane among the vehicles holding ring connectors of the roundabout ahead, or about to ask for one
    (front within :data:`ABOUT_TO_ENTER_M` of their own line; 0 almost always). Counting the ones
    about to enter keeps two buses from meeting at the lines of each other's exit arms and each
    waiting for the other to go first: both hang back, and whichever is granted first goes.

    Parameters
    ----------
    sim : generator.traffic.vehicles.VehicleSim
    veh : generator.traffic.vehicles.Vehicle
        On a lane edge.
    """
    edge = sim.g.edges[veh.edge]
    if not sim.g.grid.is_roundabout(edge.node):
        return 0.0
    cache = sim.__dict__.setdefault("_ring_users", {})
    if cache.get("occ") is not sim.occ:     # once per step (occupancy is rebuilt every step)
        cache.clear()
        cache["occ"] = sim.occ
    if edge.node not in cache:
        users = dict(sim.holders.get(edge.node, {}))
        for lane, _ in _approaches(sim.g, edge.node):
            for _, other in sim.occ.get(lane.index, ()):
                if (other.edge == lane.index and other.grant is None and len(other.plan) > 1
                        and lane.length - sim.g.stop_s_from_end - (other.s + other.length / 2) < ABOUT_TO_ENTER_M):
                    users.setdefault(other.index, other.plan[1])
        # a standard car needs no setback anywhere: keep only the vehicles larger than it
        cache[edge.node] = [(vid, _key(sim.g, sim.g.edges[c])) for vid, c in users.items()
                            if sim.vehicles[vid].length > CAR_BOX_M[0] or sim.vehicles[vid].width > CAR_BOX_M[1]]
    arm, best = approach_arm(sim.g, edge), 0.0
    for vid, key in cache[edge.node]:
        if vid != veh.index:
            h = sim.vehicles[vid]
            best = max(best, setbacks(sim.g, key, (h.length, h.width), veh.width).get((arm, edge.lane), 0.0))
    return best


def waiting_clear(sim, veh, conn, occ: dict, brake: float) -> bool:
    """Whether ``veh`` may take ring connector ``conn``: every vehicle on an approach lane its box would
    swing over (a positive setback) is not granted and can still stop short of that setback at
    ``brake`` m/s^2 (so nobody already sits, or is about to sit, where it will pass).

    Parameters
    ----------
    sim : generator.traffic.vehicles.VehicleSim
    veh : generator.traffic.vehicles.Vehicle
    conn : generator.traffic.lanes.Edge
        The ring connector asked for.
    occ : dict
        ``edge -> [(s, vehicle)]`` (:meth:`VehicleSim._occupancy`).
    brake : float
        Deceleration the waiting vehicles are expected to manage, m/s^2.
    """
    key = _key(sim.g, conn)
    for lane, arm in _approaches(sim.g, conn.node):
        for s, other in occ.get(lane.index, ()):
            if other is veh or other.edge != lane.index or other.grant is not None:
                continue
            d = setbacks(sim.g, key, (veh.length, veh.width), other.width).get((arm, lane.lane), 0.0)
            if d <= 0:
                continue
            gap = lane.length - sim.g.stop_s_from_end - (s + other.length / 2) - d
            if gap < other.v ** 2 / (2 * brake) - STOP_TOL_M:
                return False
    return True
