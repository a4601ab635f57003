"""Meshes of the street grid: road surfaces with markings, sidewalks with curbs, intersections.

Pure numpy; the grid itself (segments, cross-sections, intersections) is
:mod:`generator.layout.streets`.
"""

from __future__ import annotations

import numpy as np

from generator.geometry import Mesh, merge, pose, slab
from generator.labels import class_table
from generator.layout.cross_sections import MEDIAN_W_M
from generator.layout.closures import park_mesh
from generator.layout.roundabout_meshes import island_mesh, stop_marks
from generator.layout.one_way import one_way_marks
from generator.layout.shared_streets import shared_road_mesh
from generator.layout.streets import BAY_M, CROSSWALK_U, MARK_Z_M, PARKING_START_U, STOP_U, TREE_PIT_M, Grid, Segment
from generator.materials import material_table

DASH_M, GAP_M = 3.0, 6.0   #: centre-line dash pattern


def rects(boxes: np.ndarray, z: float, cls: str, material: str) -> Mesh:
    """Many flat upward-facing rectangles at height ``z`` in one mesh.

    Parameters
    ----------
    boxes : (k, 4) float
        ``(x0, y0, x1, y1)`` per rectangle (any corner order), metres.
    """
    b = np.asarray(boxes, np.float64).reshape(-1, 4)
    x0, x1 = np.minimum(b[:, 0], b[:, 2]), np.maximum(b[:, 0], b[:, 2])
    y0, y1 = np.minimum(b[:, 1], b[:, 3]), np.maximum(b[:, 1], b[:, 3])
    keep = (x1 - x0 > 1e-6) & (y1 - y0 > 1e-6)
    x0, x1, y0, y1 = x0[keep], x1[keep], y0[keep], y1[keep]
    k = len(x0)
    zz = np.full(k, z)
    v = np.stack([np.stack([x0, y0, zz], 1), np.stack([x1, y0, zz], 1),
                  np.stack([x1, y1, zz], 1), np.stack([x0, y1, zz], 1)], 1).reshape(-1, 3)
    base = (np.arange(k) * 4)[:, None]
    f = np.concatenate([base + [0, 1, 2], base + [0, 2, 3]], 1).reshape(-1, 3)
    return Mesh(v, f, class_table().id(cls), material_table().id(material))


def _dashes(a0: float, a1: float, v0: float, v1: float, dash: float = DASH_M, gap: float = GAP_M) -> np.ndarray:
    starts = np.arange(a0, a1, dash + gap)
    return np.stack([starts, np.full_like(starts, v0), np.minimum(starts + dash, a1), np.full_like(starts, v1)], 1)


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
        marks += one_way_marks(grid, sec.one_way, L, _dashes)
    elif grid.lanes == 1:
        marks.append(_dashes(m0, m1, -0.06, 0.06))
    else:
        marks += [np.array([(m0, -0.18, m1, -0.06), (m0, 0.06, m1, 0.18)])]
        for k in range(1, grid.lanes):
            for sgn in (-1, 1):
                marks.append(_dashes(m0, m1, sgn * k * grid.lane_w - 0.06, sgn * k * grid.lane_w + 0.06))
    edge = lh if p > 0 else rh - 0.3
    marks.append(np.array([(m0, edge - 0.075, m1, edge + 0.075), (m0, -edge - 0.075, m1, -edge + 0.075)]))
    if not sec.one_way:
        marks.append(stop_marks(grid, seg))     # stop lines, or give-way lines at roundabouts
    if has_parking:
        bays = np.arange(pk0, pk1 + 1e-6, BAY_M)
        for (a, b), side in zip(((lh + 0.075, rh), (-rh, -lh - 0.075)), (1, -1)):
            if sec.strip(side) != "parking":
                continue
            marks.append(np.stack([bays - 0.05, np.full_like(bays, a), bays + 0.05, np.full_like(bays, b)], 1))
    parts.append(rects(np.concatenate(marks), z, "road_marking", "lane_paint"))
    parts.append(crosswalk_bars(grid, L))
    return merge(parts)


def crosswalk_bars(grid: Grid, length: float) -> Mesh:
    """The zebra bars of the crosswalks at both ends of a segment ``length`` metres long (segment frame)."""
    span = 2 * (grid.road_half - 0.25)
    n = int((span + 0.5) // 1.0)
    v = -(n * 1.0 - 0.5) / 2 + np.arange(n) * 1.0
    bars = []
    for u0, u1 in (CROSSWALK_U, (length - CROSSWALK_U[1], length - CROSSWALK_U[0])):
        bars.append(np.stack([np.full(n, u0), v, np.full(n, u1), v + 0.5], 1))
    return rects(np.concatenate(bars), MARK_Z_M, "crosswalk", "crosswalk_paint")


def _curb(x0: float, y0: float, x1: float, y1: float, h: float) -> Mesh:
    return slab(min(x0, x1), min(y0, y1), max(x0, x1), max(y0, y1), 0.0, h, "curb", "curb_concrete")


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
            parts += [_curb(pk0, v_in, pk1, v_back, h), _curb(pk0, v_back, pk0 + cw, v_out, h),
                      _curb(pk1 - cw, v_back, pk1, v_out, h),
                      rects([(pk0 + cw, v_back, pk1 - cw, v_out)], h, "terrain", "grass")]
    if sec.median:
        parts.append(slab(pk0, -MEDIAN_W_M / 2, pk1, MEDIAN_W_M / 2, 0.0, h, "other_ground", "curb_concrete"))
    return parts


def segment_walk_mesh(grid: Grid, seg: Segment, pits: np.ndarray | None = None) -> Mesh:
    """Curbs and sidewalks along both sides of ``seg`` between the corner squares (segment frame).

    Parameters
    ----------
    pits : (k, 2) float, optional
        Tree-pit centres ``(u, v)`` in the segment frame: soil squares 3 mm above the paving.
    """
    rh, wi, ch, h = grid.road_half, grid.walk_inner, grid.corridor_half, grid.curb_h
    u0, u1 = ch - rh, seg.length - (ch - rh)
    parts = [_curb(u0, rh, u1, wi, h), _curb(u0, -wi, u1, -rh, h),
             rects([(u0, wi, u1, ch), (u0, -ch, u1, -wi)], h, "sidewalk", "sidewalk_concrete")]
    if pits is not None and len(pits):
        r = min(TREE_PIT_M, grid.sidewalk_w) / 2
        p = np.asarray(pits, np.float64).reshape(-1, 2)
        parts.append(rects(np.c_[p - r, p + r], h + 0.003, "terrain", "soil"))
    return merge(parts)


def segment_frame_points(seg: Segment, xy: np.ndarray) -> np.ndarray:
    """(n, 2) segment-frame ``(u, v)`` of world points ``xy`` ((n, 2) metres)."""
    d = np.asarray(xy, np.float64).reshape(-1, 2) - np.asarray(seg.origin)
    return d if seg.axis == 0 else np.stack([d[:, 1], -d[:, 0]], 1)


def intersection_road_mesh(grid: Grid) -> Mesh:
    """The asphalt square of an intersection (node frame: origin at the node, axes = world axes)."""
    r = grid.road_half
    return rects([(-r, -r, r, r)], 0.0, "road", "asphalt")


def intersection_walk_mesh(grid: Grid, node: tuple[int, int]) -> Mesh:
    """Corner squares (L-shaped curb + sidewalk), where an arm is missing a curb closing it, and at a
    roundabout its island (:func:`generator.layout.roundabout_meshes.island_mesh`), and the pocket park
    of every closed segment starting here (:func:`generator.layout.closures.park_mesh`) (node frame)."""
    rh, wi, ch, h = grid.road_half, grid.walk_inner, grid.corridor_half, grid.curb_h
    parts = []
    arms = grid.arms(node)
    for sx in (-1, 1):
        for sy in (-1, 1):
            x_arm, y_arm = (0 if sx > 0 else 2) in arms, (1 if sy > 0 else 3) in arms
            # curbs only along the road edges that exist; the rest of the square is sidewalk
            if x_arm:
                parts.append(_curb(sx * rh, sy * rh, sx * ch, sy * wi, h))
            if y_arm:
                parts.append(_curb(sx * rh, sy * (wi if x_arm else rh), sx * wi, sy * ch, h))
            x_in = wi if y_arm else rh
            y_in = wi if x_arm else rh
            parts.append(rects([(sx * x_in, sy * y_in, sx * ch, sy * ch)], h, "sidewalk", "sidewalk_concrete"))
    for d in range(4):
        if d in arms:
            continue
        cap = merge([_curb(rh, -rh, wi, rh, h), rects([(wi, -rh, ch, rh)], h, "sidewalk", "sidewalk_concrete")])
        parts.append(cap.transformed(pose(yaw=d * np.pi / 2)))
    if grid.is_roundabout(node):
        parts.append(island_mesh(grid))
    parts += [park_mesh(grid, seg, node) for seg in grid.closed if seg.a == node]   # closed streets
    return merge(parts)


def margin_mesh(grid: Grid) -> Mesh:
    """The terrain ring between the built area and the town bounds (world frame)."""
    (bx0, by0), (bx1, by1) = grid.bounds
    ix0, iy0, ix1, iy1 = grid.built_rect
    ring = [(bx0, by0, bx1, iy0), (bx0, iy1, bx1, by1), (bx0, iy0, ix0, iy1), (ix1, iy0, bx1, iy1)]
    return rects(ring, grid.curb_h, "terrain", "grass")
