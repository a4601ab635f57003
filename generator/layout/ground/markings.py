"""Road markings: crosswalk bars, stop lines and give-way lines, one-way dividers and arrows.

Rectangles in the segment frame (``(u0, v0, u1, v1)``, metres; :class:`generator.layout.network.grid.Segment`).
Roundabout entries get a give-way line (two rows of short dashes across the entry lanes) where plain
ends get a solid stop line; crosswalks stay where they are (zebra crossings on the arms). A one-way
street (:mod:`generator.layout.network.one_way`) has no centre line, dashed dividers between its
lanes, one stop line and an arrow on every lane.
"""

from __future__ import annotations

import numpy as np

from generator.geometry import Mesh
from generator.layout.ground.surfaces import dashes, rects
from generator.layout.network.grid import Grid, Segment
from generator.layout.network.measures import CROSSWALK_U, MARK_Z_M, STOP_U

GIVE_WAY_DASH_M = (0.6, 0.3)   #: dash and gap of a give-way line, metres
GIVE_WAY_ROW_M = 0.15          #: depth of one row of dashes


def crosswalk_bars(grid: Grid, length: float) -> Mesh:
    """The zebra bars of the crosswalks at both ends of a segment ``length`` metres long (segment frame)."""
    span = 2 * (grid.road_half - 0.25)
    n = int((span + 0.5) // 1.0)
    v = -(n * 1.0 - 0.5) / 2 + np.arange(n) * 1.0
    bars = []
    for u0, u1 in (CROSSWALK_U, (length - CROSSWALK_U[1], length - CROSSWALK_U[0])):
        bars.append(np.stack([np.full(n, u0), v, np.full(n, u1), v + 0.5], 1))
    return rects(np.concatenate(bars), MARK_Z_M, "crosswalk", "crosswalk_paint")


def stop_marks(grid: Grid, seg: Segment) -> np.ndarray:
    """(k, 4) segment-frame ``(u0, v0, u1, v1)`` rectangles of the lines where traffic waits at both
    ends of ``seg``: the solid stop line of a plain node, the give-way line of a roundabout."""
    L, lh = seg.length, grid.lane_half
    out = []
    ends = ((seg.a, STOP_U, (0.06, lh)), (seg.b, (L - STOP_U[1], L - STOP_U[0]), (-lh, -0.06)))
    for node, (u_in, u_out), (v0, v1) in ends:
        if not grid.is_roundabout(node):
            out.append(np.array([(min(u_in, u_out), v0, max(u_in, u_out), v1)]))
            continue
        dash, gap = GIVE_WAY_DASH_M
        starts = np.arange(v0, v1 - 0.2, dash + gap)
        ends = np.minimum(starts + dash, v1)
        lo, hi = min(u_in, u_out), max(u_in, u_out)
        for r0, r1 in ((lo, lo + GIVE_WAY_ROW_M), (hi - GIVE_WAY_ROW_M, hi)):
            out.append(np.stack([np.full_like(starts, r0), starts, np.full_like(starts, r1), ends], 1))
    return np.concatenate(out)


def one_way_marks(grid, direction: int, length: float) -> list[np.ndarray]:
    """Lane markings of a one-way segment (segment frame, ``(u0, v0, u1, v1)`` rectangles, metres).

    Dashed dividers between its ``2 * lanes`` same-direction lanes (the one at ``v = 0`` included:
    no centre line), a stop line across the whole carriageway at the end the traffic arrives at,
    and an arrow on every lane after the start's crosswalk, pointing the way the lanes run.

    Parameters
    ----------
    grid : Grid
    direction : int
        +1 (traffic towards +u) or -1.
    length : float
        Segment length, metres.
    """
    lh, w = grid.lane_half, grid.lane_w
    m0, m1 = STOP_U[1], length - STOP_U[1]
    out = [dashes(m0, m1, k * w - 0.06, k * w + 0.06) for k in range(-grid.lanes + 1, grid.lanes)]
    u0, u1 = (length - STOP_U[1], length - STOP_U[0]) if direction > 0 else STOP_U
    out.append(np.array([(u0, -lh, u1, lh)]))
    u_arrow = STOP_U[1] + 2.0 if direction > 0 else length - STOP_U[1] - 2.0
    if m1 - m0 > 12.0:
        for k in range(-grid.lanes, grid.lanes):
            out.append(arrow_rects(u_arrow, (k + 0.5) * w, direction))
    return out


def arrow_rects(u: float, v: float, direction: int, length: float = 5.0) -> np.ndarray:
    """(k, 4) rectangles drawing a straight-ahead arrow on a lane: a 0.15 m shaft and a stepped head,
    from ``u`` along ``direction`` (segment frame, metres), centred on the lane at ``v``."""
    shaft = length * 0.6
    rows = [(0.0, shaft, -0.075, 0.075)]
    steps = 6
    head = length - shaft
    for i in range(steps):
        a, b = shaft + head * i / steps, shaft + head * (i + 1) / steps
        half = 0.45 * (1 - i / steps)
        rows.append((a, b, -half, half))
    r = np.array(rows)
    if direction > 0:
        return np.stack([u + r[:, 0], v + r[:, 2], u + r[:, 1], v + r[:, 3]], 1)
    return np.stack([u - r[:, 1], v + r[:, 2], u - r[:, 0], v + r[:, 3]], 1)
