"""Where walkers on the walk network could touch, and who follows whom.

Two walkers on the same route ahead of each other are kept apart by following (a gap of
``gap`` metres of route between their centres, :func:`follow_gap`): that covers every pair of
places joined by a stretch without branches (:func:`reach`). Everywhere else two walkers can
only touch inside *conflict intervals*: stretches ``[s0, s1]`` of an edge
(arc length of the centre, metres) whose footprints overlap footprints on a stretch of
another edge -- where lines cross, merge, split or (round an obstacle) share the pavement.
Intervals closer than :data:`ADJACENT_M` along a route, or in conflict, form one *cluster*;
a walker enters a cluster only with every interval it will pass there granted at once
(:mod:`generator.traffic.pedestrians.sim`), so no two walkers ever stand in conflicting intervals.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from generator.geometry.boxes import box_pairs_overlap
from generator.traffic.pedestrians import clear as wc

STRIDE_M = 0.2       #: conflicts are looked for between samples this far apart
ADJACENT_M = 1.0     #: intervals closer than this along a route share a cluster


@dataclass
class Zones:
    """Conflict intervals of a walk network.

    Attributes
    ----------
    edge, s0, s1 : (I,) int64, float64, float64
        Edge and arc-length range of the walker's centre of each interval, metres.
    cluster : (I,) int64
        Cluster of each interval.
    conflicts : list of (k,) int64
        Intervals in conflict with each interval.
    by_edge : (E, M) int64
        Intervals of each edge in order of ``s0``, padded with ``I`` (a sentinel).
    """

    edge: np.ndarray
    s0: np.ndarray
    s1: np.ndarray
    cluster: np.ndarray
    conflicts: list[np.ndarray]
    by_edge: np.ndarray


def reach(succ: list[tuple[int, ...]], length: np.ndarray, limit: float) -> list[dict[int, float]]:
    """Per edge: the edges that *must* follow it (no branch between) starting less than ``limit``
    metres after its end -> that distance. A walker on an edge always has these on its route."""
    out = []
    for e in range(len(succ)):
        best: dict[int, float] = {}
        k, d = e, 0.0
        while len(succ[k]) == 1 and d < limit:
            k = succ[k][0]
            if k == e or k in best:
                break
            best[k] = d
            d += length[k]
        out.append(best)
    return out


def follow_gap(body: wc.Body, radius: float) -> float:
    """Smallest route distance between two walkers' centres at which their footprints (``body``)
    cannot touch anywhere on a path of straights and turns of ``radius``, metres."""
    s = np.arange(0.0, 8.0, 0.02)
    a, b = 3.0, 3.0 + radius * np.pi / 2          # straight, quarter turn, straight
    th = np.clip((s - a) / radius, 0.0, np.pi / 2)
    x = np.where(s < a, s, np.where(s < b, a + radius * np.sin(th), a + radius))
    y = np.where(s < a, 0.0, np.where(s < b, radius * (1 - np.cos(th)), radius + s - b))
    box = body.boxes(np.c_[x, y], th, 0.0)
    for gap in np.arange(2 * body.hx, 4 * body.radius, 0.05):
        k = round(gap / 0.02)
        if not box_pairs_overlap(box[:-k], box[k:]).any():
            return float(gap)
    return float(4 * body.radius)


def conflict_zones(paths, succ: list[tuple[int, ...]], near: list[dict[int, float]], body: wc.Body,
                   gap: float) -> Zones:
    """The conflict intervals and clusters of the network ``paths`` / ``succ``.

    ``near`` is :func:`reach` with a limit of at least ``gap``: pairs of samples less than
    ``gap`` of branch-free route apart (either way) are left to following.
    """
    length = np.array([p.s[-1] for p in paths])
    e_of, s_of, xy, yaw = [], [], [], []
    for e, p in enumerate(paths):
        k = np.unique(np.r_[np.arange(0, len(p.s), max(1, round(STRIDE_M / max(p.s[1], 1e-9)))), len(p.s) - 1])
        e_of.append(np.full(len(k), e))
        s_of.append(p.s[k])
        xy.append(p.points[k, :2])
        yaw.append(p.headings[k])
    e_of, s_of, xy, yaw = (np.concatenate(a) for a in (e_of, s_of, xy, yaw))
    boxes = body.boxes(xy, yaw, 0.0, grow=0.05)
    pairs = cKDTree(xy).query_pairs(2 * (body.radius + 0.05), output_type="ndarray")
    i, j = pairs[:, 0], pairs[:, 1]
    # walkers on parallel lines (the two lanes of a sidewalk) touch only if laterally closer than their widths
    c, sn = np.cos(yaw[i]), np.sin(yaw[i])
    lateral = np.abs(-sn * (xy[j, 0] - xy[i, 0]) + c * (xy[j, 1] - xy[i, 1]))
    apart = (np.abs(np.sin(yaw[j] - yaw[i])) < 1e-3) & (lateral >= 2 * (body.hy + 0.05))
    i, j = i[~apart], j[~apart]
    keep = box_pairs_overlap(boxes[i], boxes[j])
    i, j = i[keep], j[keep]
    keys = np.array([e * len(paths) + f for e, r in enumerate(near) for f in r], np.int64)
    vals = np.array([d for r in near for d in r.values()], np.float64)
    order = np.argsort(keys)
    keys, vals = keys[order], vals[order]
    keep = (_route_gap(i, j, e_of, s_of, length, keys, vals) >= gap) & \
        (_route_gap(j, i, e_of, s_of, length, keys, vals) >= gap)
    i, j = i[keep], j[keep]
    raw = _raw_intervals(i, j, e_of, s_of, length)
    return _clusters(raw, length, succ)


def _route_gap(i, j, e_of, s_of, length, keys: np.ndarray, vals: np.ndarray) -> np.ndarray:
    """(k,) route distance from sample ``i`` forward to sample ``j`` (inf when none within reach);
    ``keys`` (sorted ``e * E + e2``) and ``vals`` flatten :func:`reach`."""
    out = np.full(len(i), np.inf)
    same = (e_of[i] == e_of[j]) & (s_of[j] >= s_of[i])
    out[same] = s_of[j][same] - s_of[i][same]
    if len(keys):
        key = e_of[i] * len(length) + e_of[j]
        k = np.minimum(np.searchsorted(keys, key), len(keys) - 1)
        hit = (keys[k] == key) & (e_of[i] != e_of[j])
        out[hit] = (length[e_of[i]] - s_of[i] + vals[k] + s_of[j])[hit]
    return out


def _raw_intervals(i, j, e_of, s_of, length) -> list[tuple[int, float, float, int]]:
    """Raw intervals ``(edge, s0, s1, partner)``: one per contiguous conflict between two edges, both sides."""
    a, b = np.where(e_of[i] <= e_of[j], i, j), np.where(e_of[i] <= e_of[j], j, i)
    order = np.lexsort((s_of[a], e_of[b], e_of[a]))
    a, b = a[order], b[order]
    raw: list[tuple[int, float, float, int]] = []
    start = 0
    for k in range(1, len(a) + 1):
        if k < len(a) and e_of[a[k]] == e_of[a[start]] and e_of[b[k]] == e_of[b[start]] \
                and s_of[a[k]] - s_of[a[k - 1]] <= 2.5 * STRIDE_M:
            continue
        ea, eb = int(e_of[a[start]]), int(e_of[b[start]])
        sa, sb = s_of[a[start:k]], s_of[b[start:k]]
        n = len(raw)
        raw.append((ea, max(0.0, sa.min() - STRIDE_M), min(length[ea], sa.max() + STRIDE_M), n + 1))
        raw.append((eb, max(0.0, sb.min() - STRIDE_M), min(length[eb], sb.max() + STRIDE_M), n))
        start = k
    return raw


def _find(parent: np.ndarray, x: int) -> int:
    while parent[x] != x:
        parent[x] = parent[parent[x]]
        x = parent[x]
    return x


def _clusters(raw, length: np.ndarray, succ) -> Zones:
    n_edges = len(length)
    per_edge: list[list[int]] = [[] for _ in range(n_edges)]
    for r, (e, *_rest) in enumerate(raw):
        per_edge[e].append(r)
    merged_of = np.zeros(len(raw), np.int64)
    edge, s0, s1 = [], [], []
    for e in range(n_edges):
        for r in sorted(per_edge[e], key=lambda r: raw[r][1]):
            if edge and edge[-1] == e and raw[r][1] <= s1[-1] + 0.2:
                s1[-1] = max(s1[-1], raw[r][2])
            else:
                edge.append(e)
                s0.append(raw[r][1])
                s1.append(raw[r][2])
            merged_of[r] = len(edge) - 1
    n = len(edge)
    edge, s0, s1 = np.array(edge, np.int64), np.array(s0, np.float64), np.array(s1, np.float64)
    links = [set() for _ in range(n)]
    for r, (*_rest, partner) in enumerate(raw):
        a, b = merged_of[r], merged_of[partner]
        if a != b:
            links[a].add(int(b))
    parent = np.arange(n)
    first = {}
    for k in range(n):
        first.setdefault(int(edge[k]), k)

    def union(x, y):
        parent[_find(parent, x)] = _find(parent, y)

    for k in range(n):
        for m in links[k]:
            union(k, m)
        if k + 1 < n and edge[k + 1] == edge[k] and s0[k + 1] - s1[k] < ADJACENT_M:
            union(k, k + 1)
        last = k + 1 == n or edge[k + 1] != edge[k]
        if last and length[edge[k]] - s1[k] < ADJACENT_M:
            for f in succ[edge[k]]:
                m = first.get(f)
                if m is not None and s0[m] < ADJACENT_M - (length[edge[k]] - s1[k]):
                    union(k, m)
    roots = np.array([_find(parent, k) for k in range(n)], np.int64)
    cluster = np.unique(roots, return_inverse=True)[1] if n else np.zeros(0, np.int64)
    width = max([len(per) for per in _group(edge, n_edges)] + [1])
    by_edge = np.full((n_edges, width), n, np.int64)
    for e, ks in enumerate(_group(edge, n_edges)):
        by_edge[e, :len(ks)] = ks
    return Zones(edge, s0, s1, cluster.astype(np.int64), [np.array(sorted(x), np.int64) for x in links], by_edge)


def _group(edge: np.ndarray, n_edges: int) -> list[list[int]]:
    out: list[list[int]] = [[] for _ in range(n_edges)]
    for k, e in enumerate(edge):
        out[int(e)].append(k)
    return out
