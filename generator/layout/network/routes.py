"""Camera / ego routes: closed loops along the right-hand lane centres of the street grid.

A route is a cycle of grid nodes (intersections). Each leg runs on the centre of the
outermost (right-hand) lane for its driving direction (right-hand traffic); at every turn
the two lane-centre lines are joined by a circular arc (6 m, or down to 5 m when the
intersection is tight; left turns concentric with it), and the result is sampled about every metre
with headings and arc length.

Route 0, the one :class:`generator.world.rig.Rig` follows, is a "comb" that drives the outer
ring and snakes through the inner north-south streets; route 1 is the outer ring in the
opposite direction. In a town with roundabouts, a route goes round the island of every
roundabout it passes (see below).

In a town with roundabouts :func:`route_from_nodes` hands over to :func:`route_with_roundabouts` when
the grid has roundabouts; towns without keep the original construction (and their bytes). Here a
route is a walk on the lane graph of :class:`generator.traffic.lanes.graph.LaneGraph` on the outermost
lane ``lanes - 1``: straight lane pieces between nodes and, at each node, the connector from the arm
it arrives by to the arm it leaves by -- a straight line or the quarter circle of a plain node
(the same arcs the original routes draw), the entry fillet / ring arc / exit fillet of a
roundabout (:func:`generator.layout.network.rings.ring_path`), so going straight on or turning left
at a roundabout goes round the island.
"""

from __future__ import annotations

import numpy as np

from generator.layout.network.cycles import comb_nodes, expand_cycle, ring_nodes, turning
from generator.layout.network.design_vehicle import MIN_RADIUS_M, RIGHT_RADIUS_M
from generator.layout.network.grid import Grid
from generator.layout.network.measures import ARM_DIRS
from generator.layout.network.rings import entry_distance, plain_path, ring_path
from generator.world.scene import Path

STEP_M = 1.0            #: sampling step along a route


def route_from_nodes(grid: Grid, nodes: list[tuple[int, int]], name: str, step: float = STEP_M) -> Path:
    """Sample the closed lane-centre loop through the node cycle ``nodes``.

    Returns
    -------
    Path
        ``points`` (n, 3) float64 on the road surface (z = 0), ``headings`` (n,) radians,
        ``s`` (n,) arc length; ``closed=True``. It starts where the turn at ``nodes[0]`` ends,
        at the beginning of a straight leg.
    """
    if grid.roundabouts:    # towns without roundabouts keep this construction (and their bytes)
        return route_with_roundabouts(grid, turning(nodes), name, step)
    nodes = turning(nodes)
    xy = np.array([grid.node_xy(n) for n in nodes])
    k = len(xy)
    dirs = [(xy[(i + 1) % k] - xy[i]) / np.linalg.norm(xy[(i + 1) % k] - xy[i]) for i in range(k)]
    off = (grid.lanes - 0.5) * grid.lane_w
    # a right-turn arc bulges towards the corner by (1 - 1/sqrt 2) r: keep it 0.3 m inside the square
    r_right = max(MIN_RADIUS_M, min(RIGHT_RADIUS_M, (grid.road_half - 0.3 - off) / (1 - np.sqrt(0.5))))
    corners = []  # per node: (tangent-in point, tangent-out point, arc centre, radius, heading in, turn sign)
    for i in range(k):
        a, b = dirs[i - 1], dirs[i]
        right_a, right_b = np.array([a[1], -a[0]]), np.array([b[1], -b[0]])
        c = xy[i] + off * right_a + off * right_b
        sign = np.sign(a[0] * b[1] - a[1] * b[0])          # +1 left turn, -1 right turn
        r = r_right if sign < 0 else r_right + 2 * off
        t_in, t_out = c - r * a, c + r * b
        centre = t_in + r * sign * np.array([-a[1], a[0]])
        corners.append((t_in, t_out, centre, r, float(np.arctan2(a[1], a[0])), sign))
    pts, hds = [], []
    for i in range(k):      # straight leg i (from the end of turn i), then turn i + 1
        t_out = corners[i][1]
        t_in, _, centre, r, h0, sign = corners[(i + 1) % k]
        length = float(np.linalg.norm(t_in - t_out))
        n = max(1, int(np.ceil(length / step)))
        pts.append(t_out + (t_in - t_out) * (np.arange(n)[:, None] / n))
        hds.append(np.full(n, np.arctan2(dirs[i][1], dirs[i][0])))
        n = max(2, int(np.ceil(r * np.pi / 2 / step)))
        ang = h0 + sign * np.pi / 2 * np.arange(n) / n
        radial = ang - sign * np.pi / 2          # from the arc centre to the point, normal to the heading
        pts.append(centre + r * np.stack([np.cos(radial), np.sin(radial)], 1))
        hds.append(ang)
    p2 = np.concatenate(pts)
    heading = np.angle(np.exp(1j * np.concatenate(hds)))
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p2, axis=0), axis=1))])
    return Path(name, np.c_[p2, np.zeros(len(p2))], heading, s, closed=True)


def make_routes(grid: Grid) -> list[Path]:
    """Route 0 (comb loop) and route 1 (outer ring, the other way round)."""
    nx, ny = len(grid.xs) - 1, len(grid.ys) - 1
    return [route_from_nodes(grid, comb_nodes(nx, ny), "route_0_comb"),
            route_from_nodes(grid, ring_nodes(nx, ny, clockwise=True), "route_1_ring_cw")]


def densify(path: Path, step: float = 0.25) -> np.ndarray:
    """(m, 2) float64 xy samples of ``path`` every ``step`` metres (keep-out checks)."""
    s = np.arange(0.0, path.length(), step)
    return path.at(s)[0][:, :2]


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
