"""The pocket park of a closed street (:mod:`generator.layout.network.closures`): its sidewalks and kerbs,
grass between the kerbs at kerb height, and a footpath along the old centre line. Its trees are
placed by :mod:`generator.layout.placement.parks`.
"""

from __future__ import annotations

from generator.geometry import Mesh, merge, pose
from generator.layout.ground.sidewalks import segment_walk_mesh
from generator.layout.ground.surfaces import rects
from generator.layout.network.grid import Grid, Segment

PATH_HALF_M = 1.0     #: half width of the park's footpath


def park_mesh(grid: Grid, seg: Segment, node: tuple[int, int]) -> Mesh:
    """The closed segment ``seg`` in the frame of ``node`` (origin at the node, world axes): its two
    sidewalks with their kerbs, and between the kerbs grass (terrain) at kerb height split by a
    footpath (sidewalk) along the old centre line, from cap to cap."""
    h, rh, ch, L = grid.curb_h, grid.road_half, grid.corridor_half, seg.length
    u0, u1, p = ch - rh, L - (ch - rh), PATH_HALF_M
    local = merge([segment_walk_mesh(grid, seg),
                   rects([(u0, -rh, u1, -p), (u0, p, u1, rh)], h, "terrain", "grass"),
                   rects([(u0, -p, u1, p)], h, "sidewalk", "sidewalk_concrete")])
    c = grid.node_xy(node)
    return local.transformed(pose(seg.origin[0] - c[0], seg.origin[1] - c[1], 0.0, seg.yaw))
