"""What stands on the lots: buildings, hedges and fences along the fronts, park trees, bushes.

Every object here rests on the lot ground (z = curb height). Buildings, hedges and fences are
unique prototypes (their parameters differ); trees and bushes share a few variants.
"""

from __future__ import annotations

import numpy as np

from generator.layout.lots.lot import Lot
from generator.layout.placement.placer import Placer
from generator.layout.placement.prototypes import Proto
from generator.rng import stream
from generator.spec.model import SceneSpec

N_TREE_VARIANTS = 8
N_BUSH_VARIANTS = 5
FENCE_STYLES = ("bars", "pickets", "panels")
LOT_INSET_M = 0.05      #: every part of a building stays this far inside its lot


def tree_variant(placer: Placer, spec: SceneSpec, i: int) -> Proto:
    lo, hi = spec.heights.tree_m
    return placer.lib.variant("tree", i % N_TREE_VARIANTS, lambda g: {"height": float(g.uniform(lo, hi))})


def bush_variant(placer: Placer, i: int) -> Proto:
    return placer.lib.variant("bush", i % N_BUSH_VARIANTS, lambda g: {"size": float(g.uniform(0.7, 1.6))})


def place_buildings(placer: Placer, spec: SceneSpec, lots: list[Lot], curb_h: float) -> None:
    """One unique building prototype per lot with a building plan (dropped if it cannot fit)."""
    for lot in lots:
        plan = lot.building
        if plan is None:
            continue
        proto = placer.lib.unique("building", footprint=plan.footprint, height=plan.height,
                                  floor_height=plan.floor_height, facade=plan.facade, roof=plan.roof)
        # eaves and sills reach past the footprint: keep the whole mesh inside the lot
        a0, a1 = plan.center[0] + proto.lo[0], plan.center[0] + proto.hi[0]
        b0, b1 = plan.center[1] + proto.lo[1], plan.center[1] + proto.hi[1]
        shift = max(0.0, LOT_INSET_M - b0)
        if (a0 < -lot.width / 2 + LOT_INSET_M or a1 > lot.width / 2 - LOT_INSET_M
                or b1 + shift > lot.depth - LOT_INSET_M):
            placer.lib.discard(proto)
            lot.building, lot.use = None, "yard"
            continue
        plan.center = (plan.center[0], plan.center[1] + shift)
        x, y = lot.to_world([plan.center])[0]
        attrs = dict(plan.attrs, facade=plan.facade, roof=plan.roof, lot=lot.index)
        if not placer.try_place(proto, x, y, curb_h, lot.yaw, attrs):
            placer.lib.discard(proto)
            lot.building, lot.use = None, "yard"


def place_fronts(placer: Placer, spec: SceneSpec, lots: list[Lot], curb_h: float) -> None:
    """Hedge and fence pieces along lot fronts, one object per straight piece (tight hull proxies)."""
    g = stream(spec.seed, "layout", "fronts")
    for lot in lots:
        if not lot.front:
            continue
        height = float(g.uniform(0.9, 1.6))
        depth = float(g.uniform(0.6, 0.9))
        style = FENCE_STYLES[int(g.integers(len(FENCE_STYLES)))]
        if lot.front_height is not None:        # the lot's district drew it
            height = lot.front_height
        attrs = {"lot": lot.index, "district": lot.district} if lot.district else {"lot": lot.index}
        for piece in lot.front:
            length = piece.a1 - piece.a0
            if piece.kind == "hedge":
                proto = placer.lib.unique("hedge", length=length, height=height, depth=depth)
            else:
                proto = placer.lib.unique("fence", length=length, height=height, style=style)
            mid = (piece.a0 + piece.a1) / 2
            x, y = lot.to_world([(piece.b, mid) if piece.across else (mid, piece.b)])[0]
            yaw = lot.yaw + np.pi / 2 if piece.across else lot.yaw
            if not placer.try_place(proto, x, y, curb_h, yaw, dict(attrs)):
                placer.lib.discard(proto)


def _scatter(placer: Placer, lot: Lot, protos, n: int, margin: float, curb_h: float,
             g: np.random.Generator, pad: float) -> None:
    """Try to drop ``n`` objects (random variant from ``protos(i)``) at random spots of ``lot``."""
    w, d = lot.width / 2 - margin, lot.depth - margin
    if w <= 0 or d <= margin:
        return
    placed = tries = 0
    while placed < n and tries < 6 * n:
        tries += 1
        a, b = g.uniform(-w, w), g.uniform(margin, d)
        x, y = lot.to_world([(a, b)])[0]
        proto = protos(int(g.integers(1 << 16)))
        if placer.try_place(proto, x, y, curb_h, float(g.uniform(0, 2 * np.pi)), pad=pad):
            placed += 1


def place_lot_greenery(placer: Placer, spec: SceneSpec, lots: list[Lot], curb_h: float) -> None:
    """Trees in parks (and a few in yards) and bushes in every green lot."""
    g_trees = stream(spec.seed, "layout", "park_trees")
    g_bush = stream(spec.seed, "layout", "bushes")
    dens = spec.density
    for lot in lots:
        area = lot.width * lot.depth
        green = lot.greenery            # 1 without districts (then the counts are as they always were)
        if lot.use == "park":
            n = int(round(area / 140 * g_trees.uniform(0.7, 1.3) * green))
        elif lot.use == "yard":
            n = int(g_trees.poisson(area / 400 * green))
        else:
            n = int(g_trees.poisson(0.4 * green)) if lot.ground == "grass" else 0
        _scatter(placer, lot, lambda i: tree_variant(placer, spec, i), n, 2.5, curb_h, g_trees, pad=0.4)
        if lot.ground != "grass":
            continue
        scale = 3.0 if lot.use == "park" else 1.5
        n = int(g_bush.poisson(dens.bushes_per_100m * (lot.width + 2 * lot.depth) / 100 * scale / 3 * green))
        _scatter(placer, lot, lambda i: bush_variant(placer, i), n, 1.0, curb_h, g_bush, pad=0.2)
