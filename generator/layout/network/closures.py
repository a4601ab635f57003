"""Closed streets: a share of the interior street segments closed to traffic, made pocket parks.

Where a segment is closed, the two blocks on either side are joined by a park: its sidewalks and
kerbs stay (people still walk along them), the carriageway between the kerbs becomes grass at
kerb height with a footpath along the middle (:func:`generator.layout.ground.parks.park_mesh`,
built with the start node's corner pieces by
:func:`generator.layout.ground.intersections.intersection_walk_mesh`; trees by
:mod:`generator.layout.placement.parks`), and its two end nodes lose that arm: they become
T-junctions (or, on the outer ring, straight-through nodes), capped by a kerb like the outer
ring's. No lane, connector, crosswalk, parking bay or route uses it.

Eligible segments: not on the outer ring, not driven by routes 0 and 1
(:func:`generator.layout.network.cycles.route_pairs`, whose node cycles do not depend on the
closures), and closing one must leave every node at least two arms and the street network connected. Draws:
stream ``("layout", "closed_streets")``, one uniform draw per segment in segment order; an eligible
segment whose draw is below ``streets.closed_streets`` is closed if the rules still hold.
"""

from __future__ import annotations

from generator.layout.network.cycles import route_pairs
from generator.rng import stream


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
    """The closed :class:`generator.layout.network.grid.Segment` s of ``grid`` (empty without the field)."""
    share = 0.0 if spec.streets is None else float(spec.streets.closed_streets)
    if share <= 0:
        return ()
    nx, ny = len(grid.xs) - 1, len(grid.ys) - 1
    draws = stream(spec.seed, "layout", "closed_streets").random(len(grid.segments))
    on_route = route_pairs(nx, ny)
    open_pairs = {frozenset((s.a, s.b)) for s in grid.segments}
    closed = []
    for seg, r in zip(grid.segments, draws, strict=True):
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


def closed_record(grid) -> list | None:
    """The closed segments as node pairs, for metadata (None without any)."""
    return [[list(s.a), list(s.b)] for s in grid.closed] or None
