"""Ballasted tram track beside the street: where a town has trams, the line also runs on its own bed.

:func:`generator.layout.placement.extras.place_trams` stands each tram on grooved rails laid in a
street lane (class ``road``: drivable, as Cityscapes counts street track). Tram lines also leave the
street: along a park or a yard they run on a reserved track, a ballast bed with sleepers and rails
(:func:`assets_procedural.tracks.rail_track`, class ``rail_track``: Cityscapes "rail track" 10,
SemanticKITTI other-ground 49). For every tram placed, one straight piece of that track is laid
along the front of an open lot (a park, else a yard) that lines the tram's street, the nearest to
the tram first, parallel to the street and clear of the lot's hedge or fence; if no such lot has
room, the nearest open lot of the town that has is used. A tram with nowhere to go is logged.

No draws but the track prototypes' own (the asset stream of each piece): a town without trams is
unchanged.
"""

from __future__ import annotations

import logging

import numpy as np

from generator.layout.lots.lot import FRONT_B, Lot
from generator.layout.placement.placer import Placer
from generator.layout.placement.street_frame import Street
from generator.spec.model import SceneSpec

log = logging.getLogger(__name__)

MIN_PIECE_M = 6.0      #: shortest piece worth laying
END_CLEAR_M = 0.5      #: the piece ends this far inside the lot's sides
HEDGE_CLEAR_M = 1.0    #: bed edge behind the hedge/fence centre line (FRONT_B)
BED_HALF_M = 1.7       #: half the widest bed (assets_procedural.tracks.rail_track: 3.0-3.4 m)
STEP_M = 0.5           #: offsets into the lot tried, in steps of this


def _candidates(lots: list[Lot], tram_xy: np.ndarray, tram_yaw: float, reach: float) -> list[Lot]:
    """Open lots, the ones lining the tram's street first (parks before yards), each group nearest first."""
    d = np.array([np.cos(tram_yaw), np.sin(tram_yaw)])
    lining, other = [], []
    for lot in lots:
        if lot.use not in ("park", "yard") or lot.width < MIN_PIECE_M + 2 * END_CLEAR_M:
            continue
        off = np.asarray(lot.origin) - tram_xy
        along, across = abs(float(off @ d)), abs(float(off[0] * d[1] - off[1] * d[0]))
        parallel = abs(np.sin(lot.yaw - tram_yaw)) < 1e-3
        key = (lot.use != "park", along if parallel and across <= reach else float(np.hypot(*off)))
        (lining if parallel and across <= reach else other).append((key, lot.index, lot))
    return [lot for _, _, lot in sorted(lining)] + [lot for _, _, lot in sorted(other)]


def _lay(placer: Placer, lot: Lot, h: float) -> bool:
    """One piece along ``lot``'s front, as near the front as it fits; False if it fits nowhere."""
    length = lot.width - 2 * END_CLEAR_M
    proto = placer.lib.unique("rail_track", length=float(length))
    b0 = FRONT_B + HEDGE_CLEAR_M + BED_HALF_M
    for b in np.arange(b0, lot.depth - BED_HALF_M - END_CLEAR_M + 1e-9, STEP_M):
        x, y = lot.to_world([(0.0, float(b))])[0]
        if placer.try_place(proto, x, y, h, lot.yaw, {"lot": lot.index, "placement": "tram_track"}):
            return True
    placer.lib.discard(proto)
    return False


def place_tram_track(placer: Placer, spec: SceneSpec, lots: list[Lot], st: Street) -> None:
    """A reserved track piece for every tram placed (see the module docstring)."""
    if spec.density.trams <= 0:
        return
    trams = [p for p in placer.placed if p.kind == "tram"]
    used: set[int] = set()
    reach = st.grid.corridor_half + st.grid.road_half    # a lot on either side of the tram's street
    for tram in trams:
        T = tram.transform
        yaw = float(np.arctan2(T[1, 0], T[0, 0]))
        for lot in _candidates(lots, T[:2, 3], yaw, reach):
            if lot.index not in used and _lay(placer, lot, st.h):
                used.add(lot.index)
                break
        else:
            log.info("no open lot has room for the reserved track of the tram at (%.1f, %.1f)", *T[:2, 3])
