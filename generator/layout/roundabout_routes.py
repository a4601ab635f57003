"""Routes through towns with roundabouts: the node cycle expanded to every node it passes, each node
crossed on the connector of the route's lane (round the island at a roundabout).

:func:`generator.layout.routes.route_from_nodes` hands over to :func:`route_with_roundabouts` when
the grid has roundabouts; towns without keep the original construction (and their bytes). Here a
route is a walk on the lane graph of :class:`generator.traffic.lanes.LaneGraph` on the outermost
lane ``lanes - 1``: straight lane pieces between nodes and, at each node, the connector from the arm
it arrives by to the arm it leaves by -- a straight line or the quarter circle of a plain node
(the same arcs the original routes draw), the entry fillet / ring arc / exit fillet of a
roundabout (:func:`generator.layout.roundabouts.ring_path`), so going straight on or turning left
at a roundabout goes round the island.
"""

from __future__ import annotations

import numpy as np

from generator.layout.roundabouts import ARM_DIRS, entry_distance, plain_path, ring_path
from generator.world.scene import Path


def expand_cycle(nodes: list[tuple[int, int]]) -> list[tuple[int, int]]:
    """Every grid node the closed cycle ``nodes`` passes through, in order (first not repeated;
    consecutive cycle nodes share a row or a column)."""
    out = []
    for k, a in enumerate(nodes):
        b = nodes[(k + 1) % len(nodes)]
        d = np.sign(np.subtract(b, a)).astype(int)
        n = int(np.abs(np.subtract(b, a)).sum())
        out += [(a[0] + int(d[0]) * t, a[1] + int(d[1]) * t) for t in range(n)]
    return out


def _arm(node, nb) -> int:
    return int(np.argmax(ARM_DIRS @ np.sign(np.subtract(nb, node))))


def route_with_roundabouts(grid, nodes: list[tuple[int, int]], name: str, step: float) -> Path:
    """Sample the closed loop of the node cycle ``nodes`` on lane ``grid.lanes - 1``.

    Returns
    -------
    Path
        ``points`` (n, 3) float64 on the road surface (z = 0), about ``step`` metres apart,
        ``headings`` (n,) radians, ``s`` (n,) arc length, ``closed=True``. It starts where the
        connector at the first turning node ends, at the beginning of a lane piece.
    """
    full = expand_cycle(nodes)
    m, k = len(full), grid.lanes - 1
    entry = entry_distance(grid.lanes, grid.lane_w, grid.road_half)
    pieces = []
    for i, node in enumerate(full):
        x, y = _arm(node, full[i - 1]), _arm(node, full[(i + 1) % m])
        c0 = grid.node_xy(node)
        if grid.is_roundabout(node):
            pieces.append(ring_path(grid.ring, c0, x, y, k))
        else:
            pieces.append(plain_path(entry, grid.lane_w, c0, x, y, k))
    # dense polyline: connector i, then the lane piece to connector i + 1, starting after connector 0
    pts, hds = [], []
    for i in range(m):
        p0, p1 = pieces[i].points[-1, :2], pieces[(i + 1) % m].points[0, :2]
        n = max(1, int(np.ceil(np.linalg.norm(p1 - p0) / 0.25)))
        pts.append(p0 + (p1 - p0) * (np.arange(n)[:, None] / n))
        hds.append(np.full(n, np.arctan2(*(p1 - p0)[::-1])))
        nxt = pieces[(i + 1) % m]
        pts.append(nxt.points[:-1, :2])
        hds.append(nxt.headings[:-1])
    p2, hd = np.concatenate(pts), np.unwrap(np.concatenate(hds))
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p2, axis=0), axis=1))])
    total = s[-1] + float(np.linalg.norm(p2[0] - p2[-1]))
    n = max(4, int(np.ceil(total / step)))
    t = np.linspace(0.0, total, n, endpoint=False)
    close = hd[-1] + float(np.angle(np.exp(1j * (hd[0] - hd[-1]))))   # back to the first sample, unwrapped
    ss, p2c, hdc = np.append(s, total), np.vstack([p2, p2[:1]]), np.append(hd, close)
    xy = np.stack([np.interp(t, ss, p2c[:, 0]), np.interp(t, ss, p2c[:, 1])], 1)
    heading = np.angle(np.exp(1j * np.interp(t, ss, hdc)))
    s_out = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(xy, axis=0), axis=1))])
    return Path(name, np.c_[xy, np.zeros(len(xy))], heading, s_out, closed=True)
