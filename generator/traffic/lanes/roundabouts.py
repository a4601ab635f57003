"""Right of way at roundabouts: which connectors round the island conflict.

At a roundabout node (:mod:`generator.layout.network.roundabouts`) every connector runs round the island
anticlockwise (entry fillet, ring arc, exit fillet), so most pairs share some of the ring. There
are no signal heads: the priority rule is the simulator's grant (:mod:`generator.traffic.vehicles.sim`).
A vehicle on the ring holds its connector until its rear has left the node, and a vehicle waiting
at the give-way line is granted its connector only while no vehicle holds a conflicting one --
it yields to every vehicle on (or already committed to) the part of the ring it will use. Two
connectors conflict when a standard car on one (from the give-way line to past the far crosswalk)
can touch a standard car on the other, measured with the same padded boxes as the plain nodes'
table (:func:`generator.traffic.lanes.conflicts.conflicts`); vehicles following each other on the *same*
connector are kept apart by car-following.

People on the crosswalks of the arms: with no signal to hold vehicles back, a vehicle asks for its
connector only within ``GIVE_WAY_REQUEST_M`` of the give-way line, and is granted it only if no
person is on, or will step onto, either crosswalk it crosses in the next ``GIVE_WAY_CLEAR_S``
seconds -- long enough to clear both from a near stop. The people's own schedule is the node's
walk phase (:class:`generator.traffic.lanes.signals.Signals`), which vehicles see but no longer obey.

The table is the same for every roundabout (one cross-section, one :class:`Ring`), keyed like
the plain table: ``(arm_in, arm_out, lane) -> set of (arm_in, arm_out, lane)``.
"""

from __future__ import annotations

import numpy as np

from generator.geometry.boxes import quads_overlap
from generator.layout.network.rings import ring_path
from generator.traffic.lanes.conflicts import padded_boxes, with_lanes

GIVE_WAY_REQUEST_M = 8.0   #: at a roundabout a vehicle asks for its connector this close to the give-way line
GIVE_WAY_CLEAR_S = 14.0    #: ... and only when nobody is on or steps onto its crosswalks this long


def _ring_extended(graph, x: int, y: int, k: int, ext: float) -> np.ndarray:
    """(n, 3) x, y, heading samples of the ring connector ``(x, y, k)`` of a roundabout centred on the
    origin, with ``ext`` metres of its lanes on each side, about every 0.5 m."""
    p = ring_path(graph.grid.ring, np.zeros(2), x, y, k)
    return with_lanes(p, x, y, ext, np.searchsorted(p.s, np.arange(0.0, p.s[-1], 0.5)))


def ring_conflicts(graph, size) -> dict:
    """Which ring connectors ``(arm_in, arm_out, lane)`` conflict (every pair whose padded boxes of
    ``size`` (length, width) metres can touch), measured at a roundabout centred on the origin."""
    lanes = graph.grid.lanes
    keys = [(x, y, k) for x in range(4) for y in range(4) if x != y for k in range(lanes)]
    ext = graph.stop_m - graph.entry_m + size[0] / 2
    geo = {key: padded_boxes(_ring_extended(graph, *key, ext), size) for key in keys}
    out = {k: set() for k in keys}
    for i, ka in enumerate(keys):
        for kb in keys[i:]:
            if ka == kb or quads_overlap(geo[ka], geo[kb]).any():
                out[ka].add(kb)
                out[kb].add(ka)
    return out
