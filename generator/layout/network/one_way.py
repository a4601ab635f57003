"""Which way a one-way street runs: the routes' driving directions and a connected network.

The lane markings of a one-way street are :func:`generator.layout.ground.markings.one_way_marks`.

A street segment drawn ``one_way`` (:mod:`generator.layout.network.cross_sections`) carries all its
lanes in one direction, ``+1`` (towards its ``+u``, from node ``a`` to node ``b``) or ``-1``.
The direction is not free:

* a segment a route drives (:mod:`generator.layout.network.cycles`: route 0 "comb", route 1 the outer
  ring the other way) runs in the route's direction; a segment both routes drive in opposite
  directions cannot be one-way and keeps a two-way type;
* the street network stays *strongly connected* (from every intersection a vehicle can reach
  every other one legally), so no lane is a dead end and no vehicle is trapped. Candidates are
  accepted one by one in segment order; one that would break connectivity stays two-way;
* with closed streets (:mod:`generator.layout.network.closures`) a closed segment is never one-way and
  connectivity is that of the open streets;
* a segment ending at a roundabout (:mod:`generator.layout.network.roundabouts`) stays two-way: the ring's
  connectors, its island clearances and its conflict table are built for the slots ``0 .. lanes - 1``
  of two-way arms, and a one-way arm's left slots would have to merge on or off the ring.

Both fallbacks are deterministic (they depend on the drawn closures and roundabouts only, which
:func:`generator.layout.network.draw.make_grid` draws before the cross-sections).

Draws: the free directions come from stream ``("layout", "one_way")``, one per candidate in
segment order (none when no segment is drawn one-way, so other towns draw as before).
"""

from __future__ import annotations

from collections.abc import Sequence

from generator.layout.network.cycles import route_node_cycles
from generator.layout.network.measures import ARM_STEP
from generator.rng import stream


def driven_directions(segments: Sequence, nx: int, ny: int) -> dict[int, set[int]]:
    """``segment index -> {+1, -1, ...}``: the directions the routes drive each segment in.

    Segments no route drives are absent.
    """
    index = {(s.a, s.b): s.index for s in segments}
    out: dict[int, set[int]] = {}
    for cyc in route_node_cycles(nx, ny):
        for i, a in enumerate(cyc):
            b = cyc[(i + 1) % len(cyc)]
            if (a, b) in index:
                out.setdefault(index[(a, b)], set()).add(1)
            elif (b, a) in index:
                out.setdefault(index[(b, a)], set()).add(-1)
    return out


def strongly_connected(segments: Sequence, direction: dict[int, int]) -> bool:
    """True when a vehicle can get from every street to every other one along legal directions
    without U-turns: the graph of directed segment traversals ``(p, q)``, each followed by any
    legal ``(q, r)`` with ``r != p``, is strongly connected (so every lane has a way on, too).

    Parameters
    ----------
    segments : sequence of Segment
    direction : dict
        ``segment index -> +1 | -1`` for one-way segments; every other segment is two-way.
    """
    legal = []
    for s in segments:
        d = direction.get(s.index, 0)
        legal += [(s.a, s.b)] if d > 0 else [(s.b, s.a)] if d < 0 else [(s.a, s.b), (s.b, s.a)]
    if not legal:
        return True
    leaving: dict = {}
    arriving: dict = {}
    for p, q in legal:
        leaving.setdefault(p, []).append((p, q))
        arriving.setdefault(q, []).append((p, q))
    nexts = {t: [u for u in leaving.get(t[1], ()) if u[1] != t[0]] for t in legal}
    prevs = {t: [u for u in arriving.get(t[0], ()) if u[0] != t[1]] for t in legal}
    for adj in (nexts, prevs):
        seen, todo = {legal[0]}, [legal[0]]
        while todo:
            for u in adj[todo.pop()]:
                if u not in seen:
                    seen.add(u)
                    todo.append(u)
        if len(seen) != len(legal):
            return False
    return True


def one_way_directions(seed: int, segments: Sequence, candidates: Sequence[int], nx: int, ny: int,
                       closed: Sequence = (), roundabouts=frozenset()) -> dict[int, int]:
    """Directions of the candidate segments that can be one-way.

    Parameters
    ----------
    seed : int
        The spec's seed.
    segments : sequence of Segment
        Every segment of the grid, closed ones included (``Segment.index`` order).
    candidates : sequence of int
        Indices of the segments drawn ``one_way``, in segment order.
    nx, ny : int
        Blocks along x and y.
    closed : sequence of Segment
        Closed segments: never one-way, left out of the connectivity check.
    roundabouts : collection of (int, int)
        Roundabout nodes: a segment ending at one is never one-way.

    Returns
    -------
    dict
        ``segment index -> +1 | -1`` for the candidates accepted; the others (closed, ending at a
        roundabout, driven both ways by the routes, or breaking connectivity) are left out and fall
        back to a two-way type.
    """
    if not candidates:
        return {}
    g = stream(seed, "layout", "one_way")
    shut = {c.index for c in closed}
    open_segments = [s for s in segments if s.index not in shut]
    by_index = {s.index: s for s in segments}
    driven = driven_directions(open_segments, nx, ny)
    out: dict[int, int] = {}
    for i in candidates:
        free = 1 if g.random() < 0.5 else -1       # drawn for every candidate: later draws never shift
        dirs = driven.get(i, set())
        if len(dirs) > 1 or i in shut or by_index[i].a in roundabouts or by_index[i].b in roundabouts:
            continue
        trial = {**out, i: next(iter(dirs)) if dirs else free}
        if strongly_connected(open_segments, trial):
            out = trial
    return out


def arriving_arms(grid, node: tuple[int, int]) -> list[int]:
    """Arms of ``node`` (0 east, 1 north, 2 west, 3 south) along which traffic arrives at it.

    Every open arm of a two-way street; the arm of a one-way street only at the node its traffic
    runs to (at its other end vehicles only leave the node, so nothing approaches there).

    Parameters
    ----------
    grid : Grid
    node : tuple of int
        Intersection ``(i, j)``.
    """
    out = []
    for d in grid.arms(node):
        seg, sense = grid.segment_between(node, (node[0] + ARM_STEP[d][0], node[1] + ARM_STEP[d][1]))
        if grid.section(seg).one_way * sense <= 0:    # sense +1: leaving node along arm d is +u
            out.append(d)
    return out
