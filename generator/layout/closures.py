"""Closed streets: a share of the interior street segments closed to traffic, made pocket parks.

Where a segment is closed, the two blocks on either side are joined by a park: its sidewalks and
kerbs stay (people still walk along them), the carriageway between the kerbs becomes grass at
kerb height with a footpath along the middle (:func:`park_mesh`, built with the start node's
corner pieces by :func:`generator.layout.street_meshes.intersection_walk_mesh`; trees by
:mod:`generator.layout.placement_parks`), and its two end nodes lose that arm: they become T-junctions (or, on the outer ring, straight-through nodes), capped by a
kerb like the outer ring's. No lane, connector, crosswalk, parking bay or route uses it.

Eligible segments: not on the outer ring, not driven by routes 0 and 1
(:func:`generator.layout.routes.make_routes`, whose node cycles do not depend on the closures), and
closing one must leave every node at least two arms and the street network connected. Draws:
stream ``("layout", "closed_streets")``, one uniform draw per segment in segment order; an eligible
segment whose draw is below ``streets.closed_streets`` is closed if the rules still hold.
"""

from __future__ import annotations

import numpy as np

from generator.geometry import Mesh, merge, pose
from generator.layout.roundabout_routes import expand_cycle
from generator.layout.routes import comb_nodes, ring_nodes
from generator.rng import stream

PATH_HALF_M = 1.0     #: half width of the park's footpath


def route_pairs(nx: int, ny: int) -> set[frozenset]:
    """Node pairs ``{a, b}`` of every segment routes 0 and 1 drive on a grid of ``nx x ny`` blocks."""
    out = set()
    for cyc in (comb_nodes(nx, ny), ring_nodes(nx, ny, clockwise=True)):
        full = expand_cycle(cyc)
        out |= {frozenset((a, full[(k + 1) % len(full)])) for k, a in enumerate(full)}
    return out


def _connected(nodes: list, open_pairs: set[frozenset]) -> bool:
    adj: dict = {n: [] for n in nodes}
    for p in open_pairs:
        a, b = tuple(p)
        adj[a].append(b)
        adj[b].append(a)
    seen, todo = {nodes[0]}, [nodes[0]]
    while todo:
        for m in adj[todo.pop()]:
            if m not in seen:
                seen.add(m)
                todo.append(m)
    return len(seen) == len(nodes)


def draw_closures(spec, grid) -> tuple:
    """The closed :class:`generator.layout.streets.Segment` s of ``grid`` (empty without the field)."""
    share = 0.0 if spec.streets is None else float(spec.streets.closed_streets)
    if share <= 0:
        return ()
    nx, ny = len(grid.xs) - 1, len(grid.ys) - 1
    draws = stream(spec.seed, "layout", "closed_streets").random(len(grid.segments))
    on_route = route_pairs(nx, ny)
    open_pairs = {frozenset((s.a, s.b)) for s in grid.segments}
    closed = []
    for seg, r in zip(grid.segments, draws):
        pair = frozenset((seg.a, seg.b))
        outer = (seg.axis == 0 and seg.a[1] in (0, ny)) or (seg.axis == 1 and seg.a[0] in (0, nx))
        if r >= share or outer or pair in on_route:
            continue
        trial = open_pairs - {pair}
        degree = {n: sum(n in p for p in trial) for n in (seg.a, seg.b)}
        if min(degree.values()) >= 2 and _connected(grid.nodes, trial):
            open_pairs = trial
            closed.append(seg)
    return tuple(closed)


def open_road_rects(grid) -> np.ndarray:
    """(k, 4) float64 world AABBs of kerb-to-kerb road when some segments are closed: every open
    segment and every node square."""
    r = grid.road_half
    out = [s.rect_world(0.0, s.length, -r, r) for s in grid.segments]
    out += [(x - r, y - r, x + r, y + r) for x, y in (grid.node_xy(n) for n in grid.nodes)]
    return np.array(out, np.float64)


def closed_record(grid) -> list | None:
    """The closed segments as node pairs, for metadata (None without any)."""
    return [[list(s.a), list(s.b)] for s in grid.closed] or None


def park_mesh(grid, seg, node: tuple[int, int]) -> Mesh:
    """The closed segment ``seg`` in the frame of ``node`` (origin at the node, world axes): its two
    sidewalks with their kerbs, and between the kerbs grass (terrain) at kerb height split by a
    footpath (sidewalk) along the old centre line, from cap to cap."""
    from generator.layout.street_meshes import rects, segment_walk_mesh   # they call this module's hook

    h, rh, ch, L = grid.curb_h, grid.road_half, grid.corridor_half, seg.length
    u0, u1, p = ch - rh, L - (ch - rh), PATH_HALF_M
    local = merge([segment_walk_mesh(grid, seg),
                   rects([(u0, -rh, u1, -p), (u0, p, u1, rh)], h, "terrain", "grass"),
                   rects([(u0, -p, u1, p)], h, "sidewalk", "sidewalk_concrete")])
    c = grid.node_xy(node)
    return local.transformed(pose(seg.origin[0] - c[0], seg.origin[1] - c[1], 0.0, seg.yaw))
