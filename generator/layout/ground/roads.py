"""The road surface of a street segment: asphalt, parking strips, verges and medians, markings.

Segment frame (:class:`generator.layout.network.grid.Segment`), metres. A shared street
(cross-section ``shared``, :mod:`generator.layout.network.cross_sections`) is paved kerb to kerb
instead (material :data:`SURFACE`: small red-brown and grey concrete blocks in stretcher bond, ~0.28
LiDAR reflectivity, not the sidewalks' square grey slabs, so a camera tells the carriageway from the
pavement) and stays class ``road``: vehicles drive on it, which is what Cityscapes (7 road) and
SemanticKITTI (40 road) call road; it has no lane markings, but its stop lines and crosswalks stay.
"""

from __future__ import annotations

import numpy as np

from generator.geometry import Mesh, merge, slab
from generator.layout.ground.markings import crosswalk_bars, one_way_marks, stop_marks
from generator.layout.ground.surfaces import curb, dashes, rects
from generator.layout.network.cross_sections import MEDIAN_W_M
from generator.layout.network.grid import Grid, Segment
from generator.layout.network.measures import BAY_M, MARK_Z_M, PARKING_START_U, STOP_U

SURFACE = "block_paving"         #: material of a shared street's paved carriageway (class road)


def segment_road_mesh(grid: Grid, seg: Segment) -> Mesh:
    """Road surface, parking strips, lane markings, stop lines and crosswalks of ``seg`` (segment frame)."""
    L, lh, rh, p = seg.length, grid.lane_half, grid.road_half, grid.parking_w
    parts = [rects([(0, -lh, L, lh)], 0.0, "road", "asphalt")]
    pk0, pk1 = PARKING_START_U, L - PARKING_START_U
    has_parking = p > 0 and pk1 - pk0 >= BAY_M
    sec = grid.section(seg)
    if sec.kind == "shared":   # hook: paved kerb to kerb, no lane markings
        return shared_road_mesh(grid, seg)
    varied = has_parking and sec.strips != ("parking", "parking")
    if varied:
        parts += _strips(grid, sec, L)
    elif p > 0:
        sides = [(lh, rh), (-rh, -lh)]
        if has_parking:
            road = [(0, a, pk0, b) for a, b in sides] + [(pk1, a, L, b) for a, b in sides]
            parts.append(rects(road, 0.0, "road", "asphalt"))
            parts.append(rects([(pk0, a, pk1, b) for a, b in sides], 0.0, "parking", "parking_asphalt"))
        else:
            parts.append(rects([(0, a, L, b) for a, b in sides], 0.0, "road", "asphalt"))
    z = MARK_Z_M
    m0, m1 = STOP_U[1], L - STOP_U[1]       # markings run between the stop lines
    marks = []
    if sec.one_way:    # hook: no centre line, dashed dividers between same-direction lanes, one stop line
        marks += one_way_marks(grid, sec.one_way, L)
    elif grid.lanes == 1:
        marks.append(dashes(m0, m1, -0.06, 0.06))
    else:
        marks += [np.array([(m0, -0.18, m1, -0.06), (m0, 0.06, m1, 0.18)])]
        for k in range(1, grid.lanes):
            for sgn in (-1, 1):
                marks.append(dashes(m0, m1, sgn * k * grid.lane_w - 0.06, sgn * k * grid.lane_w + 0.06))
    edge = lh if p > 0 else rh - 0.3
    marks.append(np.array([(m0, edge - 0.075, m1, edge + 0.075), (m0, -edge - 0.075, m1, -edge + 0.075)]))
    if not sec.one_way:
        marks.append(stop_marks(grid, seg))     # stop lines, or give-way lines at roundabouts
    if has_parking:
        bays = np.arange(pk0, pk1 + 1e-6, BAY_M)
        for (a, b), side in zip(((lh + 0.075, rh), (-rh, -lh - 0.075)), (1, -1), strict=True):
            if sec.strip(side) != "parking":
                continue
            marks.append(np.stack([bays - 0.05, np.full_like(bays, a), bays + 0.05, np.full_like(bays, b)], 1))
    parts.append(rects(np.concatenate(marks), z, "road_marking", "lane_paint"))
    parts.append(crosswalk_bars(grid, L))
    return merge(parts)


def _strips(grid: Grid, sec, L: float) -> list[Mesh]:
    """The side strips of a street whose strips are not both parking (segment frame): asphalt at
    the segment ends, then per side parking asphalt, a shoulder (road) or a raised grass verge
    behind a curb; and an arterial's median island (class other_ground, curb height)."""
    lh, rh, h, cw = grid.lane_half, grid.road_half, grid.curb_h, grid.curb_w
    pk0, pk1 = PARKING_START_U, L - PARKING_START_U
    sides = {1: (lh, rh), -1: (-rh, -lh)}
    parts = [rects([(0, a, pk0, b) for a, b in sides.values()] + [(pk1, a, L, b) for a, b in sides.values()],
                   0.0, "road", "asphalt")]
    for side, (a, b) in sides.items():
        kind = sec.strip(side)
        if kind == "parking":
            parts.append(rects([(pk0, a, pk1, b)], 0.0, "parking", "parking_asphalt"))
        elif kind == "shoulder":
            parts.append(rects([(pk0, a, pk1, b)], 0.0, "road", "asphalt"))
        else:   # verge: a curb along the lane edge and both ends, grass on top at curb height
            v_in, v_out = side * lh, side * rh
            v_back = v_in + side * cw
            parts += [curb(pk0, v_in, pk1, v_back, h), curb(pk0, v_back, pk0 + cw, v_out, h),
                      curb(pk1 - cw, v_back, pk1, v_out, h),
                      rects([(pk0 + cw, v_back, pk1 - cw, v_out)], h, "terrain", "grass")]
    if sec.median:
        parts.append(slab(pk0, -MEDIAN_W_M / 2, pk1, MEDIAN_W_M / 2, 0.0, h, "other_ground", "curb_concrete"))
    return parts


def shared_road_mesh(grid: Grid, seg: Segment) -> Mesh:
    """Road surface of a shared segment (segment frame): paving kerb to kerb, stop lines, crosswalks.

    Returns
    -------
    generator.geometry.Mesh
        Class ``road`` (material :data:`SURFACE`), ``road_marking`` stop lines, ``crosswalk`` bars.
    """
    L, lh, rh = seg.length, grid.lane_half, grid.road_half
    stop = np.array([(STOP_U[0], 0.06, STOP_U[1], lh), (L - STOP_U[1], -lh, L - STOP_U[0], -0.06)])
    return merge([rects([(0, -rh, L, rh)], 0.0, "road", SURFACE),
                  rects(stop, MARK_Z_M, "road_marking", "lane_paint"), crosswalk_bars(grid, L)])
