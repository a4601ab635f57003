"""The node cycles of the two routes: which intersections route 0 ("comb") and route 1 (the outer ring,
the other way round) pass, in driving order. No geometry: the routes' lane-centre loops are
:mod:`generator.layout.network.routes`; the closures, the one-way directions and the ego's route on
the lane graph all start from these cycles.

Nodes are ``(i, j)`` grid indices on a grid of ``nx x ny`` blocks.
"""

from __future__ import annotations

import numpy as np


def comb_nodes(nx: int, ny: int) -> list[tuple[int, int]]:
    """Node cycle of the comb route on a grid of ``nx x ny`` blocks (first node not repeated).

    Counter-clockwise along the bottom and right side, then down and up the inner
    north-south streets between rows 1 and ``ny``, and down the left side home.
    """
    if ny < 2 or nx < 2:
        return ring_nodes(nx, ny, clockwise=False)
    cyc = [(0, 0), (nx, 0), (nx, ny)]
    down = True
    for c in range(nx - 1, 0, -1):
        cyc += [(c, ny), (c, 1)] if down else [(c, 1), (c, ny)]
        down = not down
    cyc.append((0, cyc[-1][1]))
    return cyc


def ring_nodes(nx: int, ny: int, clockwise: bool) -> list[tuple[int, int]]:
    """The four corner nodes of the outer ring."""
    ccw = [(0, 0), (nx, 0), (nx, ny), (0, ny)]
    return ccw[::-1] if clockwise else ccw


def turning(nodes: list[tuple[int, int]]) -> list[tuple[int, int]]:
    """Drop repeated and collinear nodes of a cycle."""
    pts = [n for k, n in enumerate(nodes) if n != nodes[k - 1]]
    out = []
    for k, n in enumerate(pts):
        a, b = np.subtract(n, pts[k - 1]), np.subtract(pts[(k + 1) % len(pts)], n)
        if a[0] * b[1] - a[1] * b[0] != 0:
            out.append(n)
    return out


def expand_cycle(nodes: list[tuple[int, int]]) -> list[tuple[int, int]]:
    """Every grid node the closed cycle ``nodes`` passes through, in order (first not repeated;
    consecutive cycle nodes share a row or a column)."""
    out = []
    for k, a in enumerate(nodes):
        b = nodes[(k + 1) % len(nodes)]
        d = np.sign(np.subtract(b, a)).astype(int)
        n = int(np.abs(np.subtract(b, a)).sum())
        out += [(a[0] + int(d[0]) * t, a[1] + int(d[1]) * t) for t in range(n)]
    return out


def route_node_cycles(nx: int, ny: int) -> list[list[tuple[int, int]]]:
    """Every node each route passes, in driving order (closed cycles, first node not repeated).

    Parameters
    ----------
    nx, ny : int
        Blocks along x and y.
    """
    out = []
    for corners in (comb_nodes(nx, ny), ring_nodes(nx, ny, clockwise=True)):
        corners = turning(corners)
        nodes = []
        for i, a in enumerate(corners):
            b = corners[(i + 1) % len(corners)]
            step = np.sign(np.subtract(b, a)).astype(int)
            n = a
            while n != b:
                nodes.append(n)
                n = (n[0] + int(step[0]), n[1] + int(step[1]))
        out.append(nodes)
    return out


def route_pairs(nx: int, ny: int) -> set[frozenset]:
    """Node pairs ``{a, b}`` of every segment routes 0 and 1 drive on a grid of ``nx x ny`` blocks."""
    out = set()
    for cyc in (comb_nodes(nx, ny), ring_nodes(nx, ny, clockwise=True)):
        full = expand_cycle(cyc)
        out |= {frozenset((a, full[(k + 1) % len(full)])) for k, a in enumerate(full)}
    return out
