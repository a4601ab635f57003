"""Outside the outer ring road: the band of lots round the town.

The outer ring road is a street like any other: beyond its outer sidewalks
(:attr:`~generator.layout.network.grid.Grid.corridor_rect`) runs a band of lots
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
The ground beyond, to the horizon, is :mod:`generator.layout.ground.terrain`.
"""

from __future__ import annotations

import numpy as np

from generator.layout.network.grid import Grid

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
        for a0, a1 in zip(a[:-1], a[1:], strict=True):
            if a1 - a0 > 1e-6:
                out.append((side, p0 + ua * a0, ua, ub, float(a1 - a0), False))
        out.append((side, p0 + ua * length, ua, ub, float(grid.outer_depth), True))
    return out
