"""Which driving lanes static objects block, for the widest vehicle that drives them.

A static object (a double-parked truck, a car left in a lane, a parked tram) blocks a lane edge
when its footprint reaches into the band a moving vehicle's box sweeps along the lane: half the
width of the widest vehicle that may drive there, mirrors included, either side of the lane
centre line, plus :data:`MARGIN_M`. The half width is measured on the prototypes the moving
traffic is drawn from (:func:`generator.traffic.vehicles.fleet.fleet_proto`: every variant of every kind
the spec asks for, and the ego), so a bus with its mirrors on arms (up to 1.5 m), a travelling
excavator (1.3-1.45 m) or a truck sets it, not a constant
(:func:`generator.traffic.vehicles.fleet.widest_half_width`). Blocked lanes leave the lane graph
(:func:`generator.traffic.build._prune`). Frames: world, metres.
"""

from __future__ import annotations

import numpy as np

from generator.geometry.boxes import corners, quad_pairs_overlap, quads_overlap
from generator.layout.network.design_vehicle import STANDARD_CAR_M

MARGIN_M = 0.05      #: clearance beyond the widest box's side, metres
SWEEP_STEP_M = 0.05  #: a turning box is checked at least every 5 cm of its path ...
SWEEP_STEP_RAD = np.radians(0.25)   #: ... and every 0.25 degrees of its turn


def too_narrow(graph, scene, half_width: float, lanes: set[int], length: float | None = None) -> set[int]:
    """The lane edges and connectors a vehicle of ``half_width`` (metres) must keep out of: those of
    ``lanes`` (kept open for the ego's route whatever stands beside them) :func:`blocked_lanes` blocks
    for that width; with its ``length`` (metres) as well, for a vehicle larger than the standard car,
    the connectors its turning box would sweep onto a static object (:func:`blocked_turns`); and then
    every lane from which each way on leads only into them (it would be stuck there). Every other
    lane of the (pruned) ``graph`` keeps a way on outside the set."""
    out = blocked_lanes(graph, scene, half_width) & set(lanes)
    if length is not None and (length > STANDARD_CAR_M[0] or 2 * half_width > STANDARD_CAR_M[1]):
        out |= blocked_turns(graph, scene, (length, 2 * half_width))
    while out:
        stuck = {e.index for e in graph.lanes() if e.index not in out and e.succ
                 and all(c in out or graph.edges[c].succ[0] in out for c in e.succ)}
        if not stuck:
            break
        out |= stuck
    return out


def blocked_turns(graph, scene, size: tuple[float, float]) -> set[int]:
    """Connectors of ``graph`` along which a box of ``size`` (length, width in metres, mirrors
    included), centred on the connector's path and :data:`MARGIN_M` larger all round, overlaps a
    static object of ``scene`` -- a long vehicle's overhang swinging over a parking strip at a
    corner (a car's box keeps inside the road there).

    Parameters
    ----------
    graph : generator.traffic.lanes.graph.LaneGraph
    scene : generator.world.scene.SceneModel
        Placed objects (instance id > 0) are the obstacles.
    size : (float, float)
        Length and width of the vehicle's box, metres.

    Returns
    -------
    set of int
        Indices of the connector edges it must not take.
    """
    memo = graph.memo.setdefault("_blocked_turn_memo", {})
    key = (id(scene), round(float(size[0]), 2), round(float(size[1]), 2))
    if key in memo:
        return memo[key]
    quads = [o.box.corners_xy() for o in scene.objects if o.instance_id > 0]
    out: set[int] = set()
    if quads:
        quads = np.stack(quads)
        centres = quads.mean(1)
        hl, hw = size[0] / 2 + MARGIN_M, size[1] / 2 + MARGIN_M
        reach = np.hypot(hl, hw) + float(np.max(np.linalg.norm(quads - centres[:, None], axis=-1)))
        swept = graph.memo.setdefault("_swept_poses", {})    # a connector's poses, whatever the size
        for e in graph.edges:
            if e.kind != "connector":
                continue
            if e.index not in swept:
                swept[e.index] = swept_poses(e.path.points[:, :2], e.path.headings)
            p, h = swept[e.index]
            lo, hi = p.min(0) - reach, p.max(0) + reach
            near = np.all((centres >= lo) & (centres <= hi), axis=1)
            if not near.any():
                continue
            if quads_overlap(corners(p, h, size, MARGIN_M), quads[near]).any():
                out.add(e.index)
    memo[key] = out
    return out


def swept_poses(p: np.ndarray, h: np.ndarray, step_m: float = SWEEP_STEP_M,
                step_rad: float = SWEEP_STEP_RAD) -> tuple[np.ndarray, np.ndarray]:
    """The poses of a path ((n, 2) points, (n,) headings) subdivided so that neighbours are at most
    ``step_m`` apart and turn by at most ``step_rad``: a 11-12 m box turning 1.6 degrees between
    the path's 0.25 m samples swings its corners 15 cm, enough to pass over a corner it touches
    in between (kitti_like seed 1: a bus's tail onto a car parked at the lane end)."""
    if len(p) < 2:
        return p, h
    hu = np.unwrap(h)
    k = np.maximum(1, np.ceil(np.maximum(np.linalg.norm(np.diff(p, axis=0), axis=1) / step_m,
                                         np.abs(np.diff(hu)) / step_rad))).astype(int)
    s = np.concatenate([i + np.arange(n) / n for i, n in enumerate(k)] + [[len(p) - 1.0]])
    i = np.arange(len(p))
    return np.stack([np.interp(s, i, p[:, 0]), np.interp(s, i, p[:, 1])], 1), np.interp(s, i, hu)


def blocked_lanes(graph, scene, half_width: float) -> set[int]:
    """Lane edges of ``graph`` (straight, one per lane and segment) a static object of ``scene``
    reaches into: its footprint overlaps the band ``half_width + MARGIN_M`` either side of the
    lane's centre line, over the lane's length.

    Parameters
    ----------
    graph : generator.traffic.lanes.graph.LaneGraph
    scene : generator.world.scene.SceneModel
        Placed objects (instance id > 0) are the obstacles.
    half_width : float
        Half width of the widest vehicle (:func:`widest_half_width`), metres.

    Returns
    -------
    set of int
        Indices of the blocked lane edges.
    """
    key = ("blocked_lanes", id(scene), float(half_width))   # asked once per moving vehicle
    if key not in graph.memo:
        graph.memo[key] = (scene, _blocked_lanes(graph, scene, half_width))   # the scene kept: its id stays its own
    return set(graph.memo[key][1])


def _blocked_lanes(graph, scene, half_width: float) -> set[int]:
    quads = [o.box.corners_xy() for o in scene.objects if o.instance_id > 0]
    if not quads:
        return set()
    quads = np.stack(quads)
    lanes, bands = graph.lanes(), []
    for e in lanes:
        p0, p1 = e.path.points[0, :2], e.path.points[-1, :2]
        d = (p1 - p0) / max(np.linalg.norm(p1 - p0), 1e-9)
        n = np.array([-d[1], d[0]]) * (half_width + MARGIN_M)
        bands.append([p0 - n, p1 - n, p1 + n, p0 + n])
    bands = np.array(bands).reshape(-1, 4, 2)
    # only pairs whose bounding boxes meet (1 mm spare) can overlap; each pair's test is its own arithmetic,
    # so testing just those gives the answer of testing every pair
    lo_b, hi_b, lo_q, hi_q = bands.min(1), bands.max(1), quads.min(1), quads.max(1)
    near = np.all((lo_b[:, None] <= hi_q[None] + 1e-3) & (lo_q[None] <= hi_b[:, None] + 1e-3), axis=-1)
    i, j = np.nonzero(near)
    hit = quad_pairs_overlap(bands[i], quads[j])
    return {lanes[k].index for k in np.unique(i[hit])}
