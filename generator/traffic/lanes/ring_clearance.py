"""Where vehicles wait at a roundabout's give-way lines while a long or wide vehicle drives the ring.

A 12 m bus (or any box much wider than a car) cannot follow a compact ring the way a car does:
its box centre keeps to the car's path, so its front overhang swings outwards on the exit fillet
and crosses the give-way line of the arm it leaves by (and a wide box reaches over the lines of
arms it passes). Real drivers see this coming: whoever arrives at a give-way line while a bus is
turning out over it holds back short of the line until the bus has gone, and a bus driver does
not pull onto the ring while a vehicle sits at the give-way line it would swing over. The
simulator does both (:mod:`generator.traffic.lanes.turn_clearance`, one rule for roundabouts and plain
intersections) from the table computed here: the *setback* of every approach lane, the distance
its vehicles must keep their front back from the give-way line so that a box waiting there stays
clear of a vehicle of a given size on a given ring connector. This is chosen over moving the
give-way line back for everyone: the painted line is laid out for cars (which need no setback),
and only the rare long vehicle should cost the others room.

Setbacks are measured at a roundabout centred on the origin (every roundabout of a town has the
same cross-section), on the connector's own samples: the holder's box (with
:data:`SETBACK_PAD_M` all round) swept along the ring connector against a waiting box of the
waiting vehicle's width whose front is on the line (:func:`sweep_setbacks`, which plain
intersections use too). The holder's own approach lane is left out (a follower there is kept
behind it by car-following). For a standard car every setback is 0, so towns whose roundabouts
see only cars drive exactly as before.
"""

from __future__ import annotations

import functools

import numpy as np

from generator.layout.network.measures import ARM_DIRS
from generator.layout.network.rings import ring_path

SETBACK_PAD_M = 0.3   #: clearance kept between a waiting box and a box on the ring, metres
STOP_TOL_M = 0.2   #: a vehicle stopped this little past its setback still counts as clear (inside the pad)
ABOUT_TO_ENTER_M = 10.0  #: a vehicle this close to its give-way line counts as about to take its connector


def approach_arm(graph, lane) -> int:
    """The arm of ``lane.node`` (a node it arrives at) that the lane edge ``lane`` comes in by."""
    key = ("approach_arm", lane.index)   # asked for every waiting vehicle every step
    if key not in graph.memo:
        d = lane.path.points[-1, :2] - graph.grid.node_xy(lane.node)
        graph.memo[key] = int(np.argmax(ARM_DIRS @ d))
    return graph.memo[key]


@functools.lru_cache(maxsize=256)
def _setbacks(ring, stop_m: float, lanes: int, key: tuple, size: tuple, wait_w: float) -> dict:
    x, y, k = key
    p = ring_path(ring, np.zeros(2), x, y, k)
    return sweep_setbacks(p.points[:, :2], p.headings, size, stop_m, ring.lane_w, range(lanes), (x, k), wait_w)


def sweep_setbacks(points: np.ndarray, headings: np.ndarray, size: tuple, stop_m: float, lane_w: float,
                   slots, own: tuple, wait_w: float) -> dict:
    """Setbacks of the approach lanes of a node centred on the origin from the boxes a holder sweeps.

    Parameters
    ----------
    points : (n, 2) float
        The holder's box centre along its connector, metres, relative to the node centre.
    headings : (n,) float
        Its heading there, radians.
    size : (float, float)
        Length and width of the holder's box, metres (padded by :data:`SETBACK_PAD_M` all round).
    stop_m : float
        Distance from the node centre to the stop (give-way) line, metres.
    lane_w : float
        Lane width, metres: slot ``k`` of an approach is centred ``(k + 0.5) * lane_w`` right of the
        arm's centre line, seen driving towards the node.
    slots : iterable of int
        The slots to measure on every arm.
    own : (int, int)
        ``(arm, slot)`` the holder comes in by (left out: car-following keeps a follower behind it).
    wait_w : float
        Width of the waiting vehicle's box, metres.

    Returns
    -------
    dict
        ``(arm, slot) -> metres`` (> 0, rounded to mm) a waiting front must keep back from the line.
    """
    hl, hw = size[0] / 2 + SETBACK_PAD_M, size[1] / 2 + SETBACK_PAD_M
    c, s = np.cos(headings)[:, None], np.sin(headings)[:, None]
    dl, dw = np.array([hl, hl, -hl, -hl]), np.array([hw, -hw, -hw, hw])
    corners = points[:, None, :2] + np.stack([c * dl - s * dw, s * dl + c * dw], -1)      # (n, 4, 2)
    n = int(np.ceil(2 * max(hl, hw) / 0.1)) + 1                                             # edges every <= 0.1 m
    pts = (corners[:, :, None] + (np.roll(corners, -1, 1) - corners)[:, :, None]
           * np.linspace(0.0, 1.0, n)[None, None, :, None]).reshape(-1, 2)
    out = {}
    for z in range(4):
        a = -ARM_DIRS[z]                           # direction of travel towards the node
        right = np.array([a[1], -a[0]])
        u = pts @ ARM_DIRS[z]                      # distance out along the arm
        for k2 in slots:
            if (z, k2) == tuple(own):
                continue
            v = pts @ right - (k2 + 0.5) * lane_w
            near = np.abs(v) < wait_w / 2
            d = float(u[near].max() - stop_m) if near.any() else -np.inf
            if d > 0:
                out[(z, k2)] = round(d, 3)
    return out


def setbacks(graph, key: tuple, size: tuple[float, float], wait_w: float) -> dict:
    """Setbacks of the approach lanes of a roundabout while a vehicle of ``size`` holds ring connector ``key``.

    Parameters
    ----------
    graph : generator.traffic.lanes.graph.LaneGraph
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
    memo = graph.memo.setdefault("_setback_memo", {})   # asked every step: skip the rounding
    got = memo.get((key, size[0], size[1], wait_w))
    if got is None:
        got = memo[(key, size[0], size[1], wait_w)] = _setbacks(
            graph.grid.ring, round(float(graph.stop_m), 3), graph.grid.lanes, tuple(int(i) for i in key),
            (round(float(size[0]), 2), round(float(size[1]), 2)), round(float(wait_w), 2))
    return got
