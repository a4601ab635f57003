"""Outside the outer ring road: the band of lots round the town and the ground to the horizon.

The outer ring road is a street like any other: beyond its outer sidewalks
(:attr:`~generator.layout.streets.Grid.corridor_rect`) runs a band of lots
``Grid.outer_depth`` deep, one row facing the ring road on each side. The four rows form a
pinwheel (each takes the corner square at its end, so they tile the band)::

        +--------+---------------------------+--------+
        | west   |  north row  (a -> east)   | north  |
        | corner +---------------------------+ corner |
        |  ^     |                           |  e     |
        |  west  |       street grid         |  a  |  |
        |  row   |   (corridor_rect)         |  s  v  |
        |  (a ^) |                           |  t     |
        | south  +---------------------------+ east   |
        | corner |  south row (a <- west)    | corner |
        +--------+---------------------------+--------+

(the corner squares drawn at the row ends: SW belongs to the south row, NW to the west row,
NE to the north row, SE to the east row). Each row is cut where the corridors of the streets
crossing its side begin and end, so a section opposite a block has the block's frontage
(and gets lots like a block's row), and a short section faces each intersection (the end of
a T-junction's street, or a corner); the corner square is one more lot (it faces along the
row, its front on the neighbouring row's side lot).

Beyond the built area and the terrain margin the ground continues as flat grass at lot
height to a regular ``HORIZON_SIDES``-gon whose edges lie :data:`HORIZON_M` beyond the far
corner of the town bounds, so from anywhere in town the ground reaches the camera's far clip
distance in every direction: the horizon band under the sky stays ground, not void.
"""

from __future__ import annotations

import numpy as np

from generator.geometry import Mesh
from generator.labels import class_table
from generator.layout.streets import Grid
from generator.materials import material_table

HORIZON_M = 2000.0     #: ground reaches this far beyond the town bounds (Blender's camera clip_end)
HORIZON_SIDES = 12     #: sides of the polygon bounding the ground (a 12-gon: 16 triangles)

#: Lot-band sides, counter-clockwise from the south: (name, a axis, b axis = away from the town).
SIDES = (("south", (-1.0, 0.0), (0.0, -1.0)), ("east", (0.0, -1.0), (1.0, 0.0)),
         ("north", (1.0, 0.0), (0.0, 1.0)), ("west", (0.0, 1.0), (-1.0, 0.0)))


def outer_rows(grid: Grid) -> list[tuple[int, np.ndarray, np.ndarray, np.ndarray, float, bool]]:
    """Sections of the outer lot band.

    Returns
    -------
    list of (side, corner, ua, ub, frontage, is_corner)
        ``side`` 0..3 (south, east, north, west); ``corner`` (2,) float64 world xy of the
        section's front-left corner (on the ring road's outer sidewalk edge, or on the
        neighbouring row's side for a corner square); ``ua`` (2,) unit vector along the
        frontage, ``ub`` (2,) unit vector into the lots (away from the town), ``ua x ub = +z``;
        ``frontage`` metres along ``ua``; ``is_corner`` for the corner square at the row's end.
        Every section is ``grid.outer_depth`` deep.
    """
    x0, y0, x1, y1 = grid.corridor_rect
    starts = ((x1, y0), (x1, y1), (x0, y1), (x0, y0))          # where each row's street frontage begins
    c = grid.corridor_half
    out = []
    for side, (_, ua, ub) in enumerate(SIDES):
        ua, ub, p0 = np.asarray(ua), np.asarray(ub), np.asarray(starts[side], np.float64)
        axis = 0 if ua[0] != 0 else 1
        lines = grid.xs if axis == 0 else grid.ys
        length = float(lines[-1] - lines[0] + 2 * c)
        a = np.unique(np.clip((np.r_[lines - c, lines + c] - p0[axis]) * ua[axis], 0.0, length))
        for a0, a1 in zip(a[:-1], a[1:]):
            if a1 - a0 > 1e-6:
                out.append((side, p0 + ua * a0, ua, ub, float(a1 - a0), False))
        out.append((side, p0 + ua * length, ua, ub, float(grid.outer_depth), True))
    return out


def _zipper(inner: np.ndarray, outer: np.ndarray) -> np.ndarray:
    """(n + m, 3) int64 triangles joining two loops around the origin (indices: inner first).

    Both loops must be star-shaped about the origin and the outer one far outside the inner
    one; each is walked counter-clockwise by angle, always advancing the loop whose next
    vertex comes first. Every triangle is returned counter-clockwise seen from above.
    """
    n, m = len(inner), len(outer)
    ang_o = np.arctan2(outer[:, 1], outer[:, 0])
    start = ang_o.min()                          # both walks start at the first outer vertex's angle
    ang_i = np.mod(np.arctan2(inner[:, 1], inner[:, 0]) - start, 2 * np.pi)
    ang_o = np.mod(ang_o - start, 2 * np.pi)
    oi, oo = np.argsort(ang_i, kind="stable"), np.argsort(ang_o, kind="stable")
    ai = np.r_[ang_i[oi], ang_i[oi[0]] + 2 * np.pi]
    ao = np.r_[ang_o[oo], ang_o[oo[0]] + 2 * np.pi]
    idx_i = lambda k: int(oi[k % n])            # noqa: E731
    idx_o = lambda k: n + int(oo[k % m])        # noqa: E731
    tris, i, j = [], 0, 0
    while i < n or j < m:
        if j == m or (i < n and ai[i + 1] <= ao[j + 1]):
            tris.append((idx_i(i), idx_i(i + 1), idx_o(j)))
            i += 1
        else:
            tris.append((idx_i(i), idx_o(j), idx_o(j + 1)))
            j += 1
    f = np.array(tris, np.int64)
    pts = np.vstack([inner, outer])
    a, b, c = pts[f[:, 0]], pts[f[:, 1]], pts[f[:, 2]]
    cw = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]) < 0
    f[cw] = f[cw][:, [0, 2, 1]]
    return f


def horizon_radius(grid: Grid) -> float:
    """Circumradius (metres from the world origin) of the polygon the ground ends at."""
    reach = float(np.hypot(*np.abs(grid.bounds).max(0)))     # the far corner of the bounds
    return (reach + HORIZON_M) / float(np.cos(np.pi / HORIZON_SIDES))


def horizon_mesh(grid: Grid) -> Mesh:
    """Flat grass (class terrain) at lot height from the town bounds out to the horizon polygon.

    World frame; ``HORIZON_SIDES + 4`` triangles, all facing up.
    """
    (bx0, by0), (bx1, by1) = grid.bounds
    inner = np.array([(bx0, by0), (bx1, by0), (bx1, by1), (bx0, by1)], np.float64)
    t = 2 * np.pi * np.arange(HORIZON_SIDES) / HORIZON_SIDES
    outer = horizon_radius(grid) * np.stack([np.cos(t), np.sin(t)], 1)
    xy = np.vstack([inner, outer])
    v = np.c_[xy, np.full(len(xy), grid.curb_h)]
    return Mesh(v, _zipper(inner, outer), class_table().id("terrain"), material_table().id("grass"))
