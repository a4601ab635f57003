"""Kerbs and sidewalks along a street segment (segment frame, metres)."""

from __future__ import annotations

import numpy as np

from generator.geometry import Mesh, merge
from generator.layout.ground.surfaces import curb, rects
from generator.layout.network.grid import Grid, Segment
from generator.layout.network.measures import TREE_PIT_M


def segment_walk_mesh(grid: Grid, seg: Segment, pits: np.ndarray | None = None) -> Mesh:
    """Curbs and sidewalks along both sides of ``seg`` between the corner squares (segment frame).

    Parameters
    ----------
    pits : (k, 2) float, optional
        Tree-pit centres ``(u, v)`` in the segment frame: soil squares 3 mm above the paving.
    """
    rh, wi, ch, h = grid.road_half, grid.walk_inner, grid.corridor_half, grid.curb_h
    u0, u1 = ch - rh, seg.length - (ch - rh)
    parts = [curb(u0, rh, u1, wi, h), curb(u0, -wi, u1, -rh, h),
             rects([(u0, wi, u1, ch), (u0, -ch, u1, -wi)], h, "sidewalk", "sidewalk_concrete")]
    if pits is not None and len(pits):
        r = min(TREE_PIT_M, grid.sidewalk_w) / 2
        p = np.asarray(pits, np.float64).reshape(-1, 2)
        parts.append(rects(np.c_[p - r, p + r], h + 0.003, "terrain", "soil"))
    return merge(parts)
