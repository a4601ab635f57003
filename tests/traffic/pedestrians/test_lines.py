"""The walk lines' street distance and its bound over a rectangle (generator/traffic/pedestrians/lines.py)."""

from __future__ import annotations

import numpy as np

from generator.layout.network.draw import make_grid
from generator.traffic.pedestrians.lines import street_distance, street_distance_bound
from kits.street_towns import full_spec


def test_the_bound_over_a_rectangle_is_its_least_street_distance_or_below():
    """Over random rectangles in and round a town with closed streets (which only raise the
    distance): no point of a rectangle is nearer the streets than its bound, and for rectangles
    away from the closed streets the nearest corner-to-corner sample comes within 1 cm of it
    (the bound is the exact minimum, not a loose one that would keep every far object)."""
    grid = make_grid(full_spec(5))
    assert grid.closed
    rng = np.random.default_rng(3)
    (x0, y0), (x1, y1) = grid.bounds[0, :2] - 80, grid.bounds[1, :2] + 80
    lo = rng.uniform([x0, y0], [x1, y1], (300, 2))
    rects = np.hstack([lo, lo + rng.uniform(0.1, 60.0, (300, 2))])
    bound = street_distance_bound(grid, rects)
    u = np.linspace(0.0, 1.0, 61)
    gx, gy = np.meshgrid(u, u)
    tight = 0
    for r, b in zip(rects, bound, strict=True):
        pts = np.column_stack([r[0] + gx.ravel() * (r[2] - r[0]), r[1] + gy.ravel() * (r[3] - r[1])])
        d = street_distance(grid, pts)
        assert d.min() >= b - 1e-12, (r, b, d.min())
        tight += bool(d.min() - b < 0.01 * max(1.0, (r[2] - r[0] + r[3] - r[1])))
    assert tight > 250
    far = np.array([[grid.bounds[1, 0] + 40, grid.bounds[0, 1], grid.bounds[1, 0] + 90, grid.bounds[1, 1]]])
    assert street_distance_bound(grid, far)[0] >= 40 - 1e-9 + (grid.bounds[1, 0] - grid.xs[-1])
