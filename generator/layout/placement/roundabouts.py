"""Roundabout furniture: a round sign at every approach, bushes on the island.

A roundabout has no signal heads (:func:`generator.layout.placement.street.place_traffic_lights`
skips it): where a signal would stand, on the near-right corner of each approach, stands a round
sign facing the approaching traffic (the town's circle sign prototype). Islands with a grass top
(:attr:`generator.layout.network.rings.Ring.grass`) get bushes
in a ring, each wholly on the grass whatever its yaw. Stream ``("layout", "roundabout_planting", i, j)`` per node.
"""

from __future__ import annotations

import numpy as np

from generator.layout.ground.islands import KERB_BAND_M
from generator.layout.placement.on_lots import bush_variant
from generator.layout.placement.placer import Placer
from generator.rng import stream

MAX_BUSHES = 6


def plant_island(placer: Placer, grid, node: tuple[int, int], seed: int, z: float) -> int:
    """Place bushes on the island of roundabout ``node`` (world frame); returns how many stood."""
    ring = grid.ring
    if ring is None or not ring.grass:
        return 0
    g = stream(seed, "layout", "roundabout_planting", node[0], node[1])
    n = int(g.integers(3, MAX_BUSHES + 1))
    phase = float(g.uniform(0.0, 2 * np.pi))
    c = grid.node_xy(node)
    placed = 0
    for k in range(n):
        a = phase + 2 * np.pi * k / n + float(g.uniform(-0.2, 0.2))
        proto = bush_variant(placer, int(g.integers(1 << 16)))
        yaw, f = float(g.uniform(0.0, 2 * np.pi)), float(g.random())
        half = float(np.hypot(*np.maximum(np.abs(proto.lo[:2]), np.abs(proto.hi[:2]))))   # any yaw
        reach = ring.core_r - KERB_BAND_M - half
        if reach <= 0.0:
            continue
        x, y = c + reach * (0.4 + 0.6 * f) * np.array([np.cos(a), np.sin(a)])
        placed += bool(placer.try_place(proto, x, y, z, yaw))
    return placed


def place_approach_signs(placer: Placer, grid, node: tuple[int, int], kerb_line: float, z: float) -> int:
    """A round sign on the near-right corner of every approach of roundabout ``node``, where a signal
    would stand at a plain node, facing the traffic; returns how many stood."""
    proto = placer.lib.variant("traffic_sign", 0, lambda g: {"shape": "circle"})
    c, placed = grid.node_xy(node), 0
    for d in grid.arms(node):
        yaw = d * np.pi / 2
        e = np.array([np.cos(yaw), np.sin(yaw)])
        x, y = c + e * kerb_line + np.array([-e[1], e[0]]) * kerb_line
        placed += bool(placer.try_place(proto, x, y, z, yaw))
    return placed
