"""Which connectors of a node conflict: a standard car on one can touch a standard car on the other.

Two connectors *conflict* when a standard car (:data:`generator.layout.network.design_vehicle.STANDARD_CAR_M`,
its box grown by :data:`CONFLICT_PAD_M`) on one, from the stop line to past the far crosswalk, can
touch one on the other. One table serves every plain node (every node has the same cross-section);
nodes with fewer arms simply lack some connectors. Keys are ``(arm_in, arm_out, lane)``, and
``(arm_in, arm_out, slot_in, slot_out)`` for the merging connectors of one-way streets
(:mod:`generator.traffic.lanes.one_way`). Roundabouts have their own table
(:mod:`generator.traffic.lanes.roundabouts`).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from generator.geometry.boxes import corners, quad_pairs_overlap
from generator.layout.network.measures import ARM_DIRS
from generator.traffic.lanes.paths import connector_path, merge_path
from generator.world.scene import Path

CONFLICT_PAD_M = 0.3   #: the standard car's box grows by this much on every side


def padded_boxes(samples: np.ndarray, size) -> np.ndarray:
    """(n, 4, 2) corners of boxes of ``size`` grown by :data:`CONFLICT_PAD_M` on the (n, 3) x, y, heading samples."""
    return corners(samples[:, :2], samples[:, 2], size, CONFLICT_PAD_M)


def with_lanes(p: Path, x: int, y: int, ext: float, keep: np.ndarray) -> np.ndarray:
    """(n, 3) x, y, heading samples of the connector path ``p`` from arm ``x`` to arm ``y`` (its samples
    ``keep``), with ``ext`` metres of its lanes before and after it, every 0.5 m."""
    a, b = -ARM_DIRS[x], ARM_DIRS[y]
    n = int(np.ceil(ext / 0.5))
    before = p.points[0, :2] - a * np.linspace(ext, 0.5, n)[:, None]
    after = p.points[-1, :2] + b * np.linspace(0.5, ext, n)[:, None]
    hb, ha = np.full(n, np.arctan2(a[1], a[0])), np.full(n, np.arctan2(b[1], b[0]))
    mid = np.c_[p.points[keep, :2], p.headings[keep]]
    return np.vstack([np.c_[before, hb], mid, np.c_[after, ha]])


def _plain_extended(entry_m: float, lane_w: float, key: tuple, ext: float) -> np.ndarray:
    """(n, 3) x, y, heading samples of the connector ``key`` at a node on the origin, with ``ext``
    metres of its lanes on each side."""
    x, y, k_in = key[:3]
    k_out = key[3] if len(key) > 3 else k_in
    p = (connector_path(np.zeros(2), entry_m, lane_w, x, y, k_in) if k_out == k_in
         else merge_path(np.zeros(2), entry_m, lane_w, x, y, k_in, k_out))
    return with_lanes(p, x, y, ext, np.r_[0:len(p.s):2, len(p.s) - 1])


@lru_cache(maxsize=16)
def conflict_table(entry_m: float, stop_m: float, lane_w: float, keys: frozenset, size) -> dict:
    """``key -> set of keys`` that conflict: a car of ``size`` (length, width, metres) on one connector,
    from the stop line to past the far crosswalk, can touch one on the other; also the table of
    two-way nodes (:func:`conflicts`). Box pairs whose centres are farther
    apart than the boxes' diameter are skipped, those closer than their width overlap without a test."""
    order = sorted(keys, key=repr)
    ext = stop_m - entry_m + size[0] / 2
    geo = [padded_boxes(_plain_extended(entry_m, lane_w, k, ext), size) for k in order]
    owner = np.concatenate([np.full(len(g), i) for i, g in enumerate(geo)])
    quads = np.concatenate(geo)
    centre = quads.mean(1)
    far = np.linalg.norm(quads[0] - centre[0], axis=1).max() * 2
    near = min(np.linalg.norm(quads[0, 1] - quads[0, 0]), np.linalg.norm(quads[0, 2] - quads[0, 1]))
    hit = np.zeros((len(order), len(order)), bool)
    for i in range(len(order)):
        rows, cols = np.flatnonzero(owner == i), np.flatnonzero(owner > i)   # each pair of keys once
        d = np.linalg.norm(centre[rows][:, None] - centre[cols][None], axis=-1)
        hit[i, owner[cols[np.nonzero(d < near)[1]]]] = True
        r, c = np.nonzero((d >= near) & (d <= far) & ~hit[i, owner[cols]][None])   # key pairs not yet decided
        over = quad_pairs_overlap(quads[rows[r]], quads[cols[c]])
        hit[i, owner[cols[c[over]]]] = True
    hit |= hit.T
    np.fill_diagonal(hit, True)
    return {k: {order[j] for j in np.flatnonzero(hit[i])} for i, k in enumerate(order)}


def conflicts(graph, size) -> dict:
    """Which connector kinds ``(arm_in, arm_out, lane)`` of ``graph`` (a
    :class:`~generator.traffic.lanes.graph.LaneGraph`) conflict, measured at a four-arm node.

    The table is the same for every node: every node has the same cross-section and entry
    distance, and a node with fewer arms simply lacks some connectors. It is
    :func:`conflict_table` on the keys of a two-way node (one
    implementation for both; cached per cross-section).
    """
    lanes = graph.grid.lanes
    keys = frozenset((x, y, k) for x in range(4) for y in range(4) if x != y for k in range(lanes))
    table = conflict_table(graph.entry_m, graph.stop_m, graph.grid.lane_w, keys, tuple(size))
    return {k: set(v) for k, v in table.items()}
