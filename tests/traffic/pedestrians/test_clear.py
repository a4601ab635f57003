"""Walkers' obstacles (generator/traffic/pedestrians/clear.py)."""

from __future__ import annotations

import numpy as np

from generator.layout.network.draw import make_grid
from generator.traffic.pedestrians import clear as wc
from generator.traffic.pedestrians.lines import street_distance, street_distance_bound
from generator.traffic.pedestrians.walkways import obstacles_of


def test_skipping_far_objects_leaves_the_same_tiles(test_spec, test_scene):
    """The walkers' obstacles skip objects wholly beyond the walkways' reach before cutting them into
    tiles (``near``): that only spares work. The test town (far city included) gives the very tiles,
    in the same order, that it gives with every object tiled and then filtered; the far city is
    what it skips (and objects deep inside the blocks)."""
    grid = make_grid(test_spec)
    body = wc.Body(0.45, 0.45, 1.95)
    reach = grid.corridor_half + 2.0
    whole = wc.Obstacles(test_scene, grid.curb_h + body.height + 0.1,
                         keep=lambda xy: street_distance(grid, xy) < reach)
    skipping = obstacles_of(grid, test_scene, body)
    assert len(whole.boxes) > 100
    assert np.array_equal(whole.boxes, skipping.boxes) and whole.reach == skipping.reach
    solid = [o for o in test_scene.objects if o.cls not in wc.GROUND_CLASSES]
    skipped = street_distance_bound(grid, wc._footprint_rects(test_scene, solid)) >= reach + 1e-6
    far = np.array([o.kind.startswith("far_") for o in solid])
    assert far.sum() >= 12 and skipped[far].mean() > 0.9   # the far city: 12 joined objects (4 sides x 3 kinds)
