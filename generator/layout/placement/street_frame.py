"""Where things stand along a street: the kerb line, the walking band, the side yaws, free lanes.

Sidewalk side ``s`` of a segment is the one at ``v * s > 0``; the traffic next to it drives
towards ``-s`` along u (right-hand traffic), so side ``-1`` serves traffic towards +u.
Furniture stands on the kerb-side line of the sidewalk, people walk in its middle, parked
vehicles sit in the parking bays, lane cars on lane centres away from every route.
"""

from __future__ import annotations

import numpy as np

from generator.layout.network.grid import Grid, Segment
from generator.layout.placement.placer import Placer
from generator.layout.placement.prototypes import Proto

N_VAR = 4   #: variants of an instanced kind of street furniture or vehicle


class Street:
    """Geometry helpers shared by the street placements."""

    def __init__(self, grid: Grid):
        self.grid = grid
        self.h = grid.curb_h
        sw = grid.sidewalk_w
        self.kerb_line = grid.walk_inner + min(0.5, sw / 2)     # |v| of poles, trunks, signs
        self.walk = (grid.walk_inner + min(1.1, sw / 2), grid.corridor_half - min(0.4, sw / 4))
        self.walk_u0 = grid.corridor_half - grid.road_half      # sidewalk starts after the corner square

    def side_yaws(self, seg: Segment, s: int) -> tuple[float, float]:
        """(yaw towards the road from side ``s``, yaw of the traffic next to side ``s``)."""
        to_road = seg.yaw + (np.pi / 2 if s < 0 else -np.pi / 2)
        traffic = seg.yaw if s < 0 else seg.yaw + np.pi
        if self.grid.section(seg).one_way:   # hook: a one-way street's traffic runs one way on both sides
            traffic = seg.yaw if self.grid.section(seg).one_way > 0 else seg.yaw + np.pi
        return to_road, traffic

    def along(self, seg: Segment, start: float, spacing: float, g: np.random.Generator) -> np.ndarray:
        """Positions u along the sidewalk of ``seg`` every ~``spacing`` metres (jittered)."""
        u0, u1 = self.walk_u0 + 0.5, seg.length - self.walk_u0 - 0.5
        steps = spacing * g.uniform(0.85, 1.15, int((u1 - u0) / (0.85 * spacing)) + 2)
        u = u0 + start + np.concatenate([[0.0], np.cumsum(steps)[:-1]])
        return u[u <= u1]


def free_lane(placer: Placer, seg: Segment, v: float, u0: float, u1: float) -> bool:
    """True if no route drives the lane whose centre is at ``v`` between ``u0`` and ``u1``."""
    tree = placer.keepout.tree
    if tree is None:
        return True
    pts = seg.to_world(np.linspace(u0, u1, 5), np.full(5, v))
    return bool(tree.query(pts)[0].min() >= placer.keepout.limit)


def variants(placer: Placer, kind: str, params_fn=None, n: int = N_VAR) -> list[Proto]:
    """Variants ``0 .. n - 1`` of an instanced ``kind`` (``params_fn(g) -> dict`` draws their parameters)."""
    return [placer.lib.variant(kind, i, params_fn) for i in range(n)]


def sides(st: Street):
    """Every ``(segment, side)`` of the town, side -1 then +1 per segment."""
    for seg in st.grid.segments:
        for s in (-1, 1):
            yield seg, s


def at(seg, u: float, v: float, proto: Proto, yaw: float) -> tuple[float, float]:
    """World xy that puts the centre of ``proto``'s body (not its local origin) at (u, v)."""
    c = (proto.lo + proto.hi) / 2
    ct, sn = np.cos(yaw), np.sin(yaw)
    x, y = seg.to_world(u, v)[0]
    return x - (c[0] * ct - c[1] * sn), y - (c[0] * sn + c[1] * ct)
