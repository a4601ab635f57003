"""Meshes of roundabouts: the raised island and the give-way lines at its entries.

The island (:attr:`generator.layout.streets.Grid.islands`), class ``other_ground`` (the class
table's traffic islands and medians): a mountable apron ``APRON_H_M`` high out to ``island_r``
and, inside it, a kerbed centre raised to curb height out to ``core_r``, with a grass top (class
``terrain``) set back by a kerb band when it is large enough (:attr:`Ring.grass`). Entries get a
give-way line (two rows of short dashes across the entry lanes) where plain ends get a solid stop
line; crosswalks stay where they are (zebra crossings on the arms).
"""

from __future__ import annotations

import numpy as np

from generator.geometry import Mesh, merge
from generator.geometry.primitives import polygon, prism
from generator.layout.streets import APRON_H_M, STOP_U, Grid, Segment

SIDES = 48             #: polygon sides of the island
KERB_BAND_M = 0.3      #: concrete band round the grass top
GIVE_WAY_DASH_M = (0.6, 0.3)   #: dash and gap of a give-way line, metres
GIVE_WAY_ROW_M = 0.15          #: depth of one row of dashes


def island_mesh(grid: Grid) -> Mesh:
    """The island of a roundabout in the node frame (origin at the node centre), metres."""
    ring = grid.ring
    a = np.linspace(0.0, 2 * np.pi, SIDES, endpoint=False)
    circle = np.stack([np.cos(a), np.sin(a)], 1)
    parts = [prism(ring.island_r * circle, 0.0, APRON_H_M, "other_ground", "curb_concrete")]
    if ring.core_r > 0:
        parts.append(prism(ring.core_r * circle, APRON_H_M, grid.curb_h, "other_ground", "curb_concrete"))
    if ring.grass:
        top = np.c_[(ring.core_r - KERB_BAND_M) * circle, np.full(SIDES, grid.curb_h + 0.003)]
        parts.append(polygon(top, "terrain", "grass", normal=(0.0, 0.0, 1.0)))
    return merge(parts)


def stop_marks(grid: Grid, seg: Segment) -> np.ndarray:
    """(k, 4) segment-frame ``(u0, v0, u1, v1)`` rectangles of the lines where traffic waits at both
    ends of ``seg``: the solid stop line of a plain node, the give-way line of a roundabout."""
    L, lh = seg.length, grid.lane_half
    out = []
    for node, (u_in, u_out), (v0, v1) in ((seg.a, STOP_U, (0.06, lh)), (seg.b, (L - STOP_U[1], L - STOP_U[0]), (-lh, -0.06))):
        if not grid.is_roundabout(node):
            out.append(np.array([(min(u_in, u_out), v0, max(u_in, u_out), v1)]))
            continue
        dash, gap = GIVE_WAY_DASH_M
        starts = np.arange(v0, v1 - 0.2, dash + gap)
        ends = np.minimum(starts + dash, v1)
        lo, hi = min(u_in, u_out), max(u_in, u_out)
        for r0, r1 in ((lo, lo + GIVE_WAY_ROW_M), (hi - GIVE_WAY_ROW_M, hi)):
            out.append(np.stack([np.full_like(starts, r0), starts, np.full_like(starts, r1), ends], 1))
    return np.concatenate(out)

