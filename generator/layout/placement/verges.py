"""Greenery on the grass verges of residential streets and boulevards (towns with ``streets``).

A verge is the raised grass strip between the lane edge and the curb
(:mod:`generator.layout.network.cross_sections`). Boulevards get a row of trees down the middle of
each verge, evenly spaced at ``100 / (2 * verge_trees_per_100m)`` metres, with low hedges between
them (each gap with probability ``verge_hedges``); residential verges
get trees at ``verge_trees_per_100m`` (jittered), low hedge pieces over ``verge_hedges`` of their
length and bushes at ``verge_bushes_per_100m`` between them.

Before the greenery, each building lot that fronts a verge gets, with probability
``density.driveways``, a *verge crossing* (class other-ground, SemanticKITTI 49): the paved
hard-standing a driveway or a house path lays across the verge, 3-4.5 m wide, from the lane-edge
kerb to the sidewalk, in front of the lot's entrance. The greenery leaves it free (a hedge piece
that would cross it is cut in two). Stream ``("layout", "verge_crossings")``.

A verge is closer to the lanes than the sidewalk's kerb line, so a crown must stay clear of the
route keep-out: at each spot the largest tree variant that the keep-out accepts stands there
(a park tree first, then street-tree variants rebuilt smaller, as on the sidewalks). Streams
``("layout", "verge_trees")`` and ``("layout", "verge_bushes")``.
"""

from __future__ import annotations

import numpy as np

from generator.layout.lots.lot import Lot
from generator.layout.network.grid import segment_frame_points
from generator.layout.placement.on_lots import N_TREE_VARIANTS, bush_variant, tree_variant
from generator.layout.placement.placer import Placer
from generator.layout.placement.street import street_tree_variants
from generator.layout.placement.street_frame import Street
from generator.rng import stream
from generator.spec.model import SceneSpec

END_CLEAR_M = 1.5     #: trees and bushes keep this far from a verge's ends (its end curbs)
CROSSING_W_M = (3.0, 4.5)   #: width of a verge crossing along the street, metres
CROSSING_CLEAR_M = 0.3      #: a hedge piece ends this far from a crossing


def _verges(st: Street):
    """(segment, side, u0, u1, v) of every verge: its usable stretch and centre line."""
    grid = st.grid
    v = grid.lane_half + grid.parking_w / 2
    for seg in grid.segments:
        span = grid.strip_span(seg)
        if span is None:
            continue
        for s in (-1, 1):
            if grid.section(seg).strip(s) == "verge":
                yield seg, s, span[0] + END_CLEAR_M, span[1] - END_CLEAR_M, s * v


def place_verge_crossings(placer: Placer, spec: SceneSpec, lots: list[Lot], st: Street) -> None:
    """Paved crossings of the verge in front of building lots (probability ``density.driveways``)."""
    dens = spec.density.driveways
    grid = st.grid
    if spec.streets is None or dens <= 0 or not grid.sections:
        return
    g = stream(spec.seed, "layout", "verge_crossings")
    verges = list(_verges(st))
    depth = grid.parking_w - grid.curb_w                 # the grass between the two kerbs
    if not verges or depth < 0.5:
        return
    v_mid = grid.lane_half + grid.curb_w + depth / 2
    b = -(grid.corridor_half - grid.road_half) - depth / 2   # lot frame: across the sidewalk, on the verge
    for lot in lots:
        if lot.use != "building":
            continue
        take, width = g.random() < dens, float(g.uniform(*CROSSING_W_M))
        a = float(np.clip(lot.entrance_a, -lot.width / 2 + width / 2, lot.width / 2 - width / 2))
        if not take or lot.width < width + 1.0:
            continue
        xy = lot.to_world([(a, b)])
        for seg, side, u0, u1, _v in verges:
            u, v = segment_frame_points(seg, xy)[0]
            if abs(v - side * v_mid) < 0.3 and u0 + width / 2 <= u <= u1 - width / 2:
                proto = placer.lib.unique("verge_crossing", width=width, depth=float(depth))
                if not placer.try_place(proto, float(xy[0, 0]), float(xy[0, 1]), st.h - 0.005, lot.yaw,
                                        {"lot": lot.index, "placement": "verge"}):
                    placer.lib.discard(proto)
                break


def _crossing_list(placer: Placer) -> list[tuple[np.ndarray, float]]:
    """(centre xy, half width) of every verge crossing placed so far."""
    return [(p.transform[:2, 3], max(p.box.size[0], p.box.size[1]) / 2) for p in placer.placed
            if p.kind == "verge_crossing"]


def _crossings(crossings, seg, v: float) -> list[tuple[float, float]]:
    """(u0, u1) spans, widened by the hedge clearance, of the ``crossings`` on ``seg``'s verge at
    centre line ``v``."""
    out = []
    for xy, half in crossings:
        u, pv = segment_frame_points(seg, xy)[0]
        if abs(pv - v) < 1.5 and -1.0 < u < seg.length + 1.0:
            out.append((u - half - CROSSING_CLEAR_M, u + half + CROSSING_CLEAR_M))
    return out


def place_verge_trees(placer: Placer, spec: SceneSpec, st: Street) -> None:
    """Tree rows on boulevard verges, scattered trees on residential verges."""
    if spec.streets is None or spec.streets.verge_trees_per_100m <= 0 or not st.grid.sections:
        return
    grid = st.grid
    g = stream(spec.seed, "layout", "verge_trees")
    crossings = _crossing_list(placer)
    route_v = (grid.lanes - 0.5) * grid.lane_w
    narrow = street_tree_variants(placer, spec, grid.lane_half + grid.parking_w / 2 - route_v
                                  - placer.keepout.limit - 0.1, tag="verge")
    wide = [tree_variant(placer, spec, i) for i in range(N_TREE_VARIANTS)]
    per_100 = spec.streets.verge_trees_per_100m
    for seg, _side, u0, u1, v in _verges(st):
        if u1 <= u0:
            continue
        boulevard = grid.section(seg).kind == "boulevard"
        spacing = 100.0 / (2 * per_100 if boulevard else per_100)
        n = int((u1 - u0) // spacing) + 1
        if boulevard:
            us = u0 + (u1 - u0 - (n - 1) * spacing) / 2 + spacing * np.arange(n)
        else:
            us = np.sort(g.uniform(u0, u1, int(g.poisson((u1 - u0) / spacing))))
        for u in us:
            x, y = seg.to_world(u, v)[0]
            yaw = seg.yaw + int(g.integers(4)) * np.pi / 2
            for proto in (wide[int(g.integers(len(wide)))], *narrow[::-1]):
                if placer.try_place(proto, x, y, st.h, yaw, {"placement": "verge"}, pad=0.3):
                    break
        if boulevard and spec.streets.verge_hedges > 0:     # shrubs between the trees of the row
            for a, b in zip(us[:-1], us[1:], strict=True):
                if g.random() < spec.streets.verge_hedges:
                    _hedge(placer, st, seg, v, a + 1.4, b - 1.4, g, crossings)


def _hedge(placer: Placer, st: Street, seg, v: float, u0: float, u1: float, g: np.random.Generator,
           crossings=()) -> None:
    """A low hedge on the verge centre line ``v`` from ``u0`` to ``u1``, cut where a verge crossing
    lies (each piece dropped if it collides; one height drawn for all its pieces)."""
    if u1 - u0 < 1.0:
        return
    grid = st.grid
    depth = max(0.3, min(0.9, grid.parking_w - grid.curb_w - 0.4))
    height = float(g.uniform(1.0, 1.8))
    pieces = []
    for c0, c1 in sorted(_crossings(crossings, seg, v)):
        if c0 < u1 and c1 > u0:
            pieces.append((u0, c0))
            u0 = max(u0, c1)
    for a, b in (*pieces, (u0, u1)):
        if b - a < 1.0:
            continue
        proto = placer.lib.unique("hedge", length=float(b - a), height=height, depth=depth)
        x, y = seg.to_world((a + b) / 2, v)[0]
        if not placer.try_place(proto, x, y, st.h, seg.yaw, {"placement": "verge"}):
            placer.lib.discard(proto)


def place_verge_bushes(placer: Placer, spec: SceneSpec, st: Street) -> None:
    """Residential verges: low hedge pieces over ``verge_hedges`` of their length (6-14 m long,
    gaps between), bushes at ``verge_bushes_per_100m`` in the rest."""
    if spec.streets is None or not st.grid.sections:
        return
    grid = st.grid
    g = stream(spec.seed, "layout", "verge_bushes")
    crossings = _crossing_list(placer)
    share, per_100 = spec.streets.verge_hedges, spec.streets.verge_bushes_per_100m
    for seg, _side, u0, u1, v in _verges(st):
        if u1 <= u0 or grid.section(seg).kind != "residential":
            continue
        u = u0 + float(g.uniform(0, 3))
        while u < u1 - 1.0:
            length = float(g.uniform(6.0, 14.0))
            if share > 0:
                gap = length * (1 - share) / max(share, 1e-3)
                length = min(length, u1 - u)
                _hedge(placer, st, seg, v, u, u + length, g, crossings)
            else:  # no hedges: the whole verge is for bushes
                gap, length = u1 - u0, 0.0
            a, b = u + length, min(u1, u + length + gap)
            for _ in range(int(g.poisson(per_100 * max(0.0, b - a) / 100))):
                x, y = seg.to_world(g.uniform(a, b), v + g.uniform(-0.3, 0.3) * grid.parking_w / 2)[0]
                placer.try_place(bush_variant(placer, int(g.integers(1 << 16))), x, y, st.h,
                                 float(g.uniform(0, 2 * np.pi)), {"placement": "verge"}, pad=0.1)
            u = b + float(g.uniform(0.5, 1.5))
