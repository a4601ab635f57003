"""Which crosswalks of a node a vehicle's box passes over on a connector.

A vehicle is granted a connector only while nobody is on, or about to step onto, a crosswalk it
will pass over (:meth:`generator.traffic.vehicles.sim.VehicleSim._maybe_grant`). The crosswalks of
the arms it comes in and leaves by are always among them; but a long box does not stay on its
path's lane: round a roundabout's compact ring its front and rear overhangs swing far outwards and
sweep the crosswalks of the arms it passes by (a 12 m bus entering from the west and leaving to the
north swings over the south and east crosswalks), and a wide box on a ring reaches them too.
:func:`swept_arms` measures this on the connector's own samples: the arms whose *crosswalk reach*
-- where any part of a person on that crosswalk can be -- the vehicle's box touches anywhere along
the connector.

The crosswalk reach of an arm: from the node centre, ``road_half + CROSSWALK_U`` out along the arm
(the painted band, where walkers' centres keep, :func:`generator.traffic.pedestrians.lines.lane_offsets`)
grown by :data:`PERSON_REACH_M` at both ends, across the whole road and :data:`PERSON_REACH_M` more.
Frames: world, metres.
"""

from __future__ import annotations

import numpy as np

from generator.geometry.boxes import corners, quad_pairs_overlap
from generator.layout.network.measures import ARM_DIRS, CROSSWALK_U

#: no part of a person lies farther than this from its centre (the largest walking pose's half
#: diagonal is about 0.65 m), metres
PERSON_REACH_M = 0.75
STEP_M = 0.1          #: the box is placed every this many metres along the connector
PAD_M = 0.05          #: ... and grown by this much, so a box between two samples is covered too


def reach_quad(grid, node, arm: int) -> np.ndarray:
    """(4, 2) corners of the crosswalk reach of ``arm`` at ``node`` (see the module docstring)."""
    d = ARM_DIRS[arm]
    n = np.array([-d[1], d[0]])
    a0 = grid.road_half + CROSSWALK_U[0] - PERSON_REACH_M
    a1 = grid.road_half + CROSSWALK_U[1] + PERSON_REACH_M
    c = grid.road_half + PERSON_REACH_M
    local = np.array([[a0, -c], [a1, -c], [a1, c], [a0, c]])
    return grid.node_xy(node) + local[:, :1] * d + local[:, 1:] * n


def swept_arms(graph, conn, size: tuple[float, float]) -> tuple[int, ...]:
    """The arms of ``conn.node`` whose crosswalk a box of ``size`` on connector ``conn`` passes over.

    Parameters
    ----------
    graph : generator.traffic.lanes.graph.LaneGraph
    conn : generator.traffic.lanes.edges.Edge
        A connector.
    size : (float, float)
        Length and width of the vehicle's box, metres (centred on the path).

    Returns
    -------
    tuple of int
        ``conn.arms`` (the crosswalks it enters and leaves by), then any other arm of the node whose
        crosswalk reach the box touches somewhere along the connector, ascending.
    """
    memo = graph.memo.setdefault("_crosswalk_sweep", {})   # asked at every grant: the geometry is fixed
    key = (conn.index, float(size[0]), float(size[1]))
    got = memo.get(key)
    if got is None:
        got = memo[key] = _swept_arms(graph, conn, size)
    return got


def _swept_arms(graph, conn, size) -> tuple[int, ...]:
    grid, path = graph.grid, conn.path
    s = np.r_[np.arange(0.0, path.s[-1], STEP_M), path.s[-1]]
    p, h = path.at(s)
    boxes = corners(p[:, :2], h, size, PAD_M)
    out = list(conn.arms)
    for arm in grid.arms(conn.node):
        if arm in out:
            continue
        quad = np.broadcast_to(reach_quad(grid, conn.node, arm), boxes.shape)
        if quad_pairs_overlap(boxes, quad).any():
            out.append(arm)
    return (*out[:2], *sorted(out[2:]))
