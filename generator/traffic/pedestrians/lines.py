"""Walking lines and the turns that join them (the geometry of :mod:`generator.traffic.pedestrians.walkways`).

Every street carries straight *lines* parallel to its centre line, two per sidewalk: the
*kerb* line at lateral offset ``a`` and the *lot* line at ``b > a`` (metres from the street
centre line, :func:`lane_offsets`). Kerb lines keep the road on the walker's right, lot
lines on the left, so people walking opposite ways on one sidewalk are ``b - a`` apart (keep
right: they never meet head-on). A line runs the whole length of its street and crosses
every arm of an intersection inside the crosswalk band.

In the corner square of every node quadrant, quarter circles of radius :data:`R_TURN` join
lines (:func:`turns`): at a block corner each family turns round the block; at an outer
corner of the town each family turns round the town; beside a missing arm (the outer ring)
the lines coming off the crosswalk turn onto the lines running past, and those turn onto the
lines going back across. World frame, metres.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from generator.layout.network.grid import Grid
from generator.layout.network.measures import CROSSWALK_U
from generator.traffic.pedestrians.clear import Body

R_TURN = 1.0        #: radius of every turn, metres
FURNITURE_M = 0.2   #: half width of a pole or trunk on the kerb-side line of a sidewalk
LOT_EDGE_M = 0.15   #: hedges and fences at the edge of a lot may reach this far onto the sidewalk
KERB, LOT = 0, 1    #: line families


@dataclass(frozen=True)
class Line:
    """A straight directed walking line along one sidewalk of one street."""

    axis: int        #: 0 runs along x (an east-west street), 1 along y
    c: float         #: the constant coordinate (y for axis 0, x for axis 1), metres
    d: int           #: +1 / -1: direction of travel along the axis
    side: int        #: +1 / -1: side of the street centre line
    fam: int         #: KERB or LOT

    def xy(self, t: np.ndarray) -> np.ndarray:
        """(n, 2) world points at along-coordinates ``t`` (n,)."""
        t = np.atleast_1d(np.asarray(t, np.float64))
        c = np.full_like(t, self.c)
        return np.stack([t, c] if self.axis == 0 else [c, t], -1)

    @property
    def u(self) -> np.ndarray:
        """(2,) unit direction of travel."""
        return np.array([self.d, 0.0] if self.axis == 0 else [0.0, self.d])

    @property
    def n(self) -> np.ndarray:
        """(2,) unit normal pointing away from the street centre line."""
        return np.array([0.0, self.side] if self.axis == 0 else [self.side, 0.0])


def lane_offsets(grid: Grid, body: Body) -> tuple[float, ...]:
    """Offsets of the kerb and lot lines from the street centre line, metres.

    Both stay inside the crosswalk band, beside the poles and trunks on the sidewalk's
    kerb-side line and clear of the hedges and fences at the lot edge; the kerb line leaves
    room between itself and the curb for a walker waiting for the signal where it can; the lot
    line is ``2 hy + 0.3`` farther out. A sidewalk too narrow for two lines gets one (kerb: the
    sidewalks become one-way), one too narrow for any gets none.
    """
    rh, wi, ch, hy = grid.road_half, grid.walk_inner, grid.corridor_half, body.hy
    furniture = wi + min(0.5, grid.sidewalk_w / 2) + FURNITURE_M        # poles and trunks stand on this side
    lo = max(rh + CROSSWALK_U[0] + hy, furniture + hy + 0.02)
    hi = min(rh + CROSSWALK_U[1] - hy, ch - LOT_EDGE_M - hy - 0.02)
    wait = wi + 2 * body.hx + 0.05 + hy + 0.35
    sep = 2 * hy + 0.3
    if hi - lo >= sep:
        a = min(max(lo, wait), hi - sep)
        return (a, min(hi, a + sep + 0.2))
    if hi < lo:                  # no room beside the furniture: in between it, round it
        lo = max(rh + CROSSWALK_U[0] + hy, wi + hy + 0.05)
    return ((lo + hi) / 2,) if hi >= lo else ()


def street_distance(grid: Grid, xy: np.ndarray) -> np.ndarray:
    """(n,) float64 L-infinity distance from (n, 2) points to the nearest street centre segment.

    Below ``road_half`` a point is on the road, between ``walk_inner`` and ``corridor_half`` on
    a sidewalk (the corner squares and the outer ring's corners included).
    """
    xy = np.asarray(xy, np.float64).reshape(-1, 2)
    xs, ys = grid.xs, grid.ys
    out_x = np.maximum.reduce([xs[0] - xy[:, 0], xy[:, 0] - xs[-1], np.zeros(len(xy))])
    out_y = np.maximum.reduce([ys[0] - xy[:, 1], xy[:, 1] - ys[-1], np.zeros(len(xy))])
    d_ew = np.maximum(np.abs(xy[:, 1, None] - ys[None]), out_x[:, None]).min(1)
    d_ns = np.maximum(np.abs(xy[:, 0, None] - xs[None]), out_y[:, None]).min(1)
    d = np.minimum(d_ew, d_ns)
    for seg in grid.closed:     # a closed street (a park at kerb height) is no street: as far as its sidewalks
        x0, y0, x1, y1 = seg.rect_world(0.0, seg.length, -grid.corridor_half, grid.corridor_half)
        inside = (xy[:, 0] > x0) & (xy[:, 0] < x1) & (xy[:, 1] > y0) & (xy[:, 1] < y1)
        d[inside] = np.maximum(d[inside], grid.corridor_half)
    return d


def street_distance_bound(grid: Grid, rects: np.ndarray) -> np.ndarray:
    """(m,) float64: a lower bound of :func:`street_distance` over each of the (m, 4) rectangles
    ``(x0, y0, x1, y1)`` -- the least L-infinity distance from the rectangle to the street centre
    segments (exact, as the distance is a max of one x and one y term per segment; a closed street
    only raises :func:`street_distance`)."""
    r = np.asarray(rects, np.float64).reshape(-1, 4)
    xs, ys = grid.xs, grid.ys
    zero = np.zeros(len(r))
    out_x = np.maximum.reduce([xs[0] - r[:, 2], r[:, 0] - xs[-1], zero])
    out_y = np.maximum.reduce([ys[0] - r[:, 3], r[:, 1] - ys[-1], zero])
    gap_y = np.maximum(np.maximum(r[:, 1, None] - ys[None], ys[None] - r[:, 3, None]), 0.0)
    gap_x = np.maximum(np.maximum(r[:, 0, None] - xs[None], xs[None] - r[:, 2, None]), 0.0)
    d_ew = np.maximum(gap_y, out_x[:, None]).min(1)
    d_ns = np.maximum(gap_x, out_y[:, None]).min(1)
    return np.minimum(d_ew, d_ns)


def lines(grid: Grid, offs: tuple[float, ...]) -> dict[tuple[int, int, int, int], Line]:
    """Every line, keyed ``(axis, street index, side, family)``."""
    out = {}
    for axis, centres in ((0, grid.ys), (1, grid.xs)):
        for k, c0 in enumerate(centres):
            for side in (-1, 1):
                kerb_d = side if axis == 0 else -side      # the road on the walker's right
                for fam, off in enumerate(offs):
                    out[(axis, k, side, fam)] = Line(axis, float(c0 + side * off), kerb_d if fam == KERB else -kerb_d,
                                                     side, fam)
    return out


def turns(grid: Grid, lines: dict, offs: tuple[float, ...]) -> list[tuple[tuple, tuple, np.ndarray]]:
    """Turns ``(key of the line in, key of the line out, corner point (2,))`` of every node quadrant."""
    out = []
    for node in grid.nodes:
        arms = grid.arms(node)
        for sx in (-1, 1):
            for sy in (-1, 1):
                xa, ya = (0 if sx > 0 else 2) in arms, (1 if sy > 0 else 3) in arms
                out += _quadrant(grid, lines, offs, node, sx, sy, xa, ya)
    return out


def _quadrant(grid: Grid, lines: dict, offs, node, sx: int, sy: int, xa: bool, ya: bool) -> list:
    """Turns in quadrant ``(sx, sy)`` of ``node``; ``xa``, ``ya``: whether its arms along x and y exist."""
    (i, j), c, fams = node, grid.node_xy(node), range(len(offs))
    xl = {f: (0, j, sy, f) for f in fams}        # lines along the east-west street
    yl = {f: (1, i, sx, f) for f in fams}        # lines along the north-south street

    def corner(fx, fy):                          # where x-line ``fx`` meets y-line ``fy``
        return c + (sx * offs[fy], sy * offs[fx])

    def toward(key):                             # heading towards the node
        return lines[key].d == -(sx if key[0] == 0 else sy)

    out = []
    if xa == ya:          # block corner (round the block) or outer corner (round the town)
        for f in fams:
            first, second = (xl[f], yl[f]) if toward(xl[f]) == xa else (yl[f], xl[f])
            if toward(first) == xa and toward(second) != xa:
                out.append((first, second, corner(f, f)))
        return out
    through, stubs = (xl, yl) if xa else (yl, xl)   # through lines cross the missing arm's cap
    for f in fams:
        arriving = not toward(stubs[f])             # came across the crosswalk of the existing arm
        for tf in fams:
            p = corner(tf, f) if xa else corner(f, tf)
            out.append((stubs[f], through[tf], p) if arriving else (through[tf], stubs[f], p))
    return out


def along(line: Line, p: np.ndarray) -> float:
    """Along-coordinate of point ``p`` (2,) on ``line``."""
    return float(p[line.axis])


def arc(p: np.ndarray, u1: np.ndarray, u2: np.ndarray, step: float) -> np.ndarray:
    """(n, 2) quarter circle from ``p - R u1`` (heading ``u1``) to ``p + R u2`` (heading ``u2``),
    points at most ``step`` metres apart."""
    n = int(np.ceil(np.pi / 2 * R_TURN / step)) + 1
    th = np.linspace(0.0, np.pi / 2, n)[:, None]
    centre = p - R_TURN * u1 + R_TURN * u2
    return centre + R_TURN * (-u2 * np.cos(th) + u1 * np.sin(th))
