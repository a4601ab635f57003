"""Roundabouts: which intersections are roundabouts (their ring: :mod:`generator.layout.network.rings`).

Only four-arm (interior) nodes can be roundabouts: a ring needs the asphalt of all four arms
round it (at a three-arm node the ring would run into the kerb closing the missing arm). A
cross-section whose ring would need arcs tighter than ``MIN_RADIUS_M``, or whose standard car
(4.8 x 2.1 m) would leave the kerb lines anywhere on a path, cannot have roundabouts: asking for
them there is a spec error (``streets.roundabouts``, exit 2).

Draws: stream ``("layout", "roundabouts")``, one uniform draw per interior node in
:attr:`generator.layout.network.grid.Grid.nodes` order; a node is a roundabout when its draw is below
``streets.roundabouts``.
"""

from __future__ import annotations

import logging

from generator.errors import SpecError
from generator.layout.network.design_vehicle import MIN_RADIUS_M
from generator.rng import stream

log = logging.getLogger(__name__)


def draw_roundabouts(spec, grid) -> frozenset:
    """The roundabout nodes of ``grid`` drawn from ``spec.streets.roundabouts`` (empty without it).

    Raises
    ------
    SpecError
        Roundabouts asked for in a town with interior nodes whose cross-section fits none.
    """
    share = 0.0 if spec.streets is None else float(spec.streets.roundabouts)
    if share <= 0:
        return frozenset()
    nx, ny = len(grid.xs) - 1, len(grid.ys) - 1
    interior = [n for n in grid.nodes if 0 < n[0] < nx and 0 < n[1] < ny]
    draws = stream(spec.seed, "layout", "roundabouts").random(len(interior))
    chosen = frozenset(n for n, r in zip(interior, draws, strict=True) if r < share)
    if interior and grid.ring is None:
        raise SpecError(spec.source or spec.name, "streets.roundabouts",
                        f"no roundabout fits streets of {grid.lanes} lane(s) of {grid.lane_w:g} m and "
                        f"{grid.parking_w:g} m parking (its arcs would be tighter than {MIN_RADIUS_M:g} m or leave "
                        f"the kerbs); widen town.lane_width_m or town.parking_strip_width_m, or set 0, got {share:g}")
    log.info("%s: %d of %d interior nodes are roundabouts", spec.name, len(chosen), len(interior))
    return chosen


def roundabout_record(grid) -> dict | None:
    """What was drawn, for metadata: the roundabout nodes and their ring geometry (None without any)."""
    if not grid.roundabouts:
        return None
    return {"nodes": [list(n) for n in sorted(grid.roundabouts)], **grid.ring.to_dict()}
