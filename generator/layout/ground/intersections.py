"""Intersections: the asphalt square and the corner pieces round it (node frame: origin at the node,
axes = world axes, metres), with a roundabout's island and the parks of closed streets starting there."""

from __future__ import annotations

import numpy as np

from generator.geometry import Mesh, merge, pose
from generator.layout.ground.islands import island_mesh
from generator.layout.ground.parks import park_mesh
from generator.layout.ground.surfaces import curb, rects
from generator.layout.network.grid import Grid


def intersection_road_mesh(grid: Grid) -> Mesh:
    """The asphalt square of an intersection (node frame: origin at the node, axes = world axes)."""
    r = grid.road_half
    return rects([(-r, -r, r, r)], 0.0, "road", "asphalt")


def intersection_walk_mesh(grid: Grid, node: tuple[int, int]) -> Mesh:
    """Corner squares (L-shaped curb + sidewalk), where an arm is missing a curb closing it, and at a
    roundabout its island (:func:`generator.layout.ground.islands.island_mesh`), and the pocket park
    of every closed segment starting here (:func:`generator.layout.ground.parks.park_mesh`) (node frame)."""
    rh, wi, ch, h = grid.road_half, grid.walk_inner, grid.corridor_half, grid.curb_h
    parts = []
    arms = grid.arms(node)
    for sx in (-1, 1):
        for sy in (-1, 1):
            x_arm, y_arm = (0 if sx > 0 else 2) in arms, (1 if sy > 0 else 3) in arms
            # curbs only along the road edges that exist; the rest of the square is sidewalk
            if x_arm:
                parts.append(curb(sx * rh, sy * rh, sx * ch, sy * wi, h))
            if y_arm:
                parts.append(curb(sx * rh, sy * (wi if x_arm else rh), sx * wi, sy * ch, h))
            x_in = wi if y_arm else rh
            y_in = wi if x_arm else rh
            parts.append(rects([(sx * x_in, sy * y_in, sx * ch, sy * ch)], h, "sidewalk", "sidewalk_concrete"))
    for d in range(4):
        if d in arms:
            continue
        cap = merge([curb(rh, -rh, wi, rh, h), rects([(wi, -rh, ch, rh)], h, "sidewalk", "sidewalk_concrete")])
        parts.append(cap.transformed(pose(yaw=d * np.pi / 2)))
    if grid.is_roundabout(node):
        parts.append(island_mesh(grid))
    parts += [park_mesh(grid, seg, node) for seg in grid.closed if seg.a == node]   # closed streets
    return merge(parts)
