"""Speed limits per lane-graph edge: shared streets are driven at walking-friendly speed.

Vehicles (:mod:`generator.traffic.vehicles`) cap their desired speed on an edge of
:func:`speed_caps` and brake for it comfortably before they reach it, as they do for turns.
"""

from __future__ import annotations

from generator.layout.network.cross_sections import SHARED_SPEED_MPS


def speed_caps(graph) -> dict[int, float]:
    """``edge index -> speed limit (m/s)`` for the lanes of shared segments and the connectors into them.

    Parameters
    ----------
    graph : generator.traffic.lanes.graph.LaneGraph

    Returns
    -------
    dict
        Empty when the town has no shared street.
    """
    grid = graph.grid
    shared = {i for i, sec in enumerate(grid.sections) if sec.kind == "shared"}
    if not shared:
        return {}
    caps = {ei: SHARED_SPEED_MPS for (si, _, _), ei in graph.lane_edge.items() if si in shared}
    for e in graph.edges:
        if e.kind == "connector" and any(n in caps for n in e.succ):
            caps[e.index] = SHARED_SPEED_MPS
    return caps
