"""Camera / ego routes: closed loops along the right-hand lane centres of the street grid.

A route is a cycle of grid nodes (intersections). Each leg runs on the centre of the
outermost (right-hand) lane for its driving direction (right-hand traffic); at every turn
the two lane-centre lines are joined by a circular arc (6 m, or down to 5 m when the
intersection is tight; left turns concentric with it), and the result is sampled about every metre with headings and arc length.

Route 0, the one :class:`generator.world.rig.Rig` follows, is a "comb" that drives the outer
ring and snakes through the inner north-south streets; route 1 is the outer ring in the
opposite direction. In a town with roundabouts, a route goes round the island of every
roundabout it passes (:mod:`generator.layout.roundabout_routes`).
"""

from __future__ import annotations

import numpy as np

from generator.layout.streets import Grid
from generator.world.scene import Path

STEP_M = 1.0            #: sampling step along a route
RIGHT_RADIUS_M = 6.0    #: preferred right-turn radius (left turns are concentric, 2 lane offsets wider)
MIN_RADIUS_M = 5.0


def comb_nodes(nx: int, ny: int) -> list[tuple[int, int]]:
    """Node cycle of the comb route on a grid of ``nx x ny`` blocks (first node not repeated).

    Counter-clockwise along the bottom and right side, then down and up the inner
    north-south streets between rows 1 and ``ny``, and down the left side home.
    """
    if ny < 2 or nx < 2:
        return ring_nodes(nx, ny, clockwise=False)
    cyc = [(0, 0), (nx, 0), (nx, ny)]
    down = True
    for c in range(nx - 1, 0, -1):
        cyc += [(c, ny), (c, 1)] if down else [(c, 1), (c, ny)]
        down = not down
    cyc.append((0, cyc[-1][1]))
    return cyc


def ring_nodes(nx: int, ny: int, clockwise: bool) -> list[tuple[int, int]]:
    """The four corner nodes of the outer ring."""
    ccw = [(0, 0), (nx, 0), (nx, ny), (0, ny)]
    return ccw[::-1] if clockwise else ccw


def _turning(nodes: list[tuple[int, int]]) -> list[tuple[int, int]]:
    """Drop repeated and collinear nodes of a cycle."""
    pts = [n for k, n in enumerate(nodes) if n != nodes[k - 1]]
    out = []
    for k, n in enumerate(pts):
        a, b = np.subtract(n, pts[k - 1]), np.subtract(pts[(k + 1) % len(pts)], n)
        if a[0] * b[1] - a[1] * b[0] != 0:
            out.append(n)
    return out


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
        from generator.layout.roundabout_routes import route_with_roundabouts

        return route_with_roundabouts(grid, _turning(nodes), name, step)
    nodes = _turning(nodes)
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
