"""Where vehicles wait while a long or wide vehicle turns through a node, and when it may go.

A 12 m bus (or a truck, or any box larger than the standard car of the conflict table) cannot
follow a car's path through a node the way a car does: its box centre keeps to the path, so on a
turn its front and rear overhangs swing to the outside of the arc. Turning right at a plain
(signalised) intersection its front swings over the opposite half of the street it turns into,
right onto a vehicle waiting at that arm's stop line; at a roundabout it swings over the give-way
line of its exit arm (:mod:`generator.traffic.lanes.ring_clearance`). Real junctions handle this with
set-back stop lines or with drivers who hold back for a turning bus; urbangen does the latter, with
one rule for both kinds of node, so only the rare long vehicle costs the others room:

* **hang back** (:func:`held_setback`): a vehicle approaching a node keeps its front back from the
  line by the *setback* of its approach lane -- the distance at which a box of its width stays
  clear of every box a large vehicle sweeps along its connector -- while a large vehicle holds a
  connector there or is about to ask for one (front within :data:`ABOUT_TO_ENTER_M` of its own
  line, so two buses at each other's swept lines both hang back and whichever is granted first
  goes);
* **wait until clear** (:func:`waiting_clear`): a large vehicle is granted its connector only while
  every vehicle on a lane it would sweep is granted itself (and leaving) or can still stop short of
  that lane's setback.

Setbacks are measured on the connector's own samples, relative to the node centre (every node of
a kind has the same cross-section), with :data:`~generator.traffic.lanes.ring_clearance.SETBACK_PAD_M`
all round (:func:`generator.traffic.lanes.ring_clearance.sweep_setbacks`). Vehicles no larger than the
standard car never make anyone hang back, and at a plain node they are granted without the check,
so towns without trucks or buses drive exactly as before. Frames: world, metres.
"""

from __future__ import annotations

from generator.layout.network.design_vehicle import STANDARD_CAR_M
from generator.traffic.lanes.ring_clearance import ABOUT_TO_ENTER_M, STOP_TOL_M, approach_arm, setbacks, sweep_setbacks


def is_large(veh) -> bool:
    """Whether vehicle ``veh`` is longer or wider than the standard car (:data:`STANDARD_CAR_M`)."""
    return veh.length > STANDARD_CAR_M[0] or veh.width > STANDARD_CAR_M[1]


def _key(graph, conn) -> tuple:
    return getattr(graph, "conflict_keys", {}).get(conn.index, (*conn.arms, conn.lane))


def node_setbacks(graph, conn, size: tuple[float, float], wait_w: float) -> dict:
    """Setbacks of the approach lanes of ``conn.node`` while a vehicle of ``size`` holds connector ``conn``.

    Parameters
    ----------
    graph : generator.traffic.lanes.graph.LaneGraph
    conn : generator.traffic.lanes.edges.Edge
        A connector (plain node or ring).
    size : (float, float)
        Length and width of the holder's box, metres.
    wait_w : float
        Width of the waiting vehicle's box, metres.

    Returns
    -------
    dict
        ``(arm, slot) -> metres`` (> 0) the front of a vehicle waiting on that approach lane must keep
        back from its stop or give-way line; lanes not listed need none.
    """
    fast = graph.memo.setdefault("_edge_setback_memo", {})   # asked every step: skip the keys and rounding
    got = fast.get((conn.index, size[0], size[1], wait_w))
    if got is None:
        got = fast[(conn.index, size[0], size[1], wait_w)] = _node_setbacks(graph, conn, size, wait_w)
    return got


def _node_setbacks(graph, conn, size: tuple[float, float], wait_w: float) -> dict:
    key = _key(graph, conn)
    if graph.grid.is_roundabout(conn.node):
        return setbacks(graph, key, size, wait_w)
    memo = graph.memo.setdefault("_plain_setback_memo", {})
    mkey = (key, round(float(size[0]), 2), round(float(size[1]), 2), round(float(wait_w), 2))
    got = memo.get(mkey)
    if got is None:   # the same connector kind sweeps the same ground at every plain node
        rel = conn.path.points[:, :2] - graph.grid.node_xy(conn.node)
        lanes = graph.grid.lanes
        got = memo[mkey] = sweep_setbacks(rel, conn.path.headings, mkey[1:3], round(float(graph.stop_m), 3),
                                          graph.grid.lane_w, range(-lanes, lanes), (key[0], key[2]), mkey[3])
    return got


def _approaches(graph, node) -> list:
    """``[(lane edge, arm)]`` of the lane edges arriving at ``node`` (cached on the graph)."""
    table = graph.memo.setdefault("_node_approaches", {})
    if not table:
        for e in graph.lanes():
            table.setdefault(e.node, []).append((e, approach_arm(graph, e)))
    return table.get(node, [])


def _large_users(sim, cache: dict) -> None:
    """Fill ``cache["users"]``: ``node -> {vehicle index: connector edge}`` of the vehicles larger than
    the standard car that hold a connector of the node or are about to ask for one (front within
    :data:`ABOUT_TO_ENTER_M` of their own line). A standard car needs no setback anywhere."""
    large = cache.get("large")
    if large is None:
        large = [v for v in sim.vehicles if is_large(v)]
    cache.clear()
    cache.update(occ=sim.occ, large=large, users={})
    users = cache["users"]
    for node, held in sim.holders.items():
        for vid, c in held.items():
            if is_large(sim.vehicles[vid]):
                users.setdefault(node, {})[vid] = c
    for other in large:
        lane = sim.g.edges[other.edge]
        if (lane.kind == "lane" and other.grant is None and len(other.plan) > 1
                and lane.length - sim.g.stop_s_from_end - (other.s + other.length / 2) < ABOUT_TO_ENTER_M):
            users.setdefault(lane.node, {}).setdefault(other.index, other.plan[1])


def held_setback(sim, veh) -> float:
    """Metres ``veh`` must now stop short of its stop (or give-way) line: the largest setback of its
    approach lane among the large vehicles holding connectors of the node ahead, or about to ask for
    one (front within :data:`ABOUT_TO_ENTER_M` of their own line); 0 almost always.

    Parameters
    ----------
    sim : generator.traffic.vehicles.sim.VehicleSim
    veh : generator.traffic.vehicles.sim.Vehicle
        On a lane edge.
    """
    edge = sim.g.edges[veh.edge]
    cache = sim.__dict__.setdefault("_node_users", {})
    if cache.get("occ") is not sim.occ:     # once per step (occupancy is rebuilt every step)
        _large_users(sim, cache)
    users = cache["users"].get(edge.node)
    if not users:
        return 0.0
    arm, best = approach_arm(sim.g, edge), 0.0
    for vid, c in users.items():
        if vid != veh.index:
            h = sim.vehicles[vid]
            sb = node_setbacks(sim.g, sim.g.edges[c], (h.length, h.width), veh.width)
            best = max(best, sb.get((arm, edge.lane), 0.0))
    return best


def waiting_clear(sim, veh, conn, occ: dict, brake: float) -> bool:
    """Whether ``veh`` may take connector ``conn``: every vehicle on an approach lane its box would
    swing over (a positive setback) is not granted and can still stop short of that setback at
    ``brake`` m/s^2 (so nobody already sits, or is about to sit, where it will pass).

    Parameters
    ----------
    sim : generator.traffic.vehicles.sim.VehicleSim
    veh : generator.traffic.vehicles.sim.Vehicle
    conn : generator.traffic.lanes.edges.Edge
        The connector asked for.
    occ : dict
        ``edge -> [(s, vehicle)]`` (:meth:`VehicleSim._occupancy`).
    brake : float
        Deceleration the waiting vehicles are expected to manage, m/s^2.
    """
    for lane, arm in _approaches(sim.g, conn.node):
        for s, other in occ.get(lane.index, ()):
            if other is veh or other.edge != lane.index or other.grant is not None:
                continue
            d = node_setbacks(sim.g, conn, (veh.length, veh.width), other.width).get((arm, lane.lane), 0.0)
            if d <= 0:
                continue
            gap = lane.length - sim.g.stop_s_from_end - (s + other.length / 2) - d
            if gap < other.v ** 2 / (2 * brake) - STOP_TOL_M:
                return False
    return True
