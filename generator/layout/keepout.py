"""The route keep-out: objects keep ``limit`` metres (2D) from every route sample.

Distances from route samples to an object's footprint: an oriented box
(:func:`point_box_distance`) or, for the parallelogram a skewed town makes of a shaped object's
box, a convex polygon (:func:`point_polygon_distance`). Frames: whichever frame the samples are in
(grid or world), metres.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from generator.world.scene import OrientedBox


class Keepout:
    """Route samples every 25 cm; objects must keep ``limit`` metres (2D) away from all of them."""

    def __init__(self, samples_xy: np.ndarray, limit: float):
        self.points = np.asarray(samples_xy, np.float64).reshape(-1, 2)
        self.limit = float(limit)
        self.tree = cKDTree(self.points) if len(self.points) else None

    def distance(self, box: OrientedBox) -> float:
        """2D distance from the box footprint to the nearest route sample within reach (inf if none)."""
        if self.tree is None:
            return np.inf
        r = float(np.hypot(box.size[0], box.size[1]) / 2 + self.limit + 0.5)
        idx = self.tree.query_ball_point(box.center[:2], r)
        if not idx:
            return np.inf
        return float(point_box_distance(self.points[idx], box).min())

    def violated(self, box: OrientedBox) -> bool:
        return self.distance(box) < self.limit

    def polygon_distance(self, polygon: np.ndarray) -> float:
        """2D distance from a convex (k, 2) polygon (counter-clockwise) to the nearest route sample
        within reach (inf if none)."""
        if self.tree is None:
            return np.inf
        poly = np.asarray(polygon, np.float64).reshape(-1, 2)
        c = poly.mean(0)
        idx = self.tree.query_ball_point(c, float(np.linalg.norm(poly - c, axis=1).max() + self.limit + 0.5))
        if not idx:
            return np.inf
        return float(point_polygon_distance(self.points[idx], poly).min())


def point_box_distance(points: np.ndarray, box: OrientedBox) -> np.ndarray:
    """(n,) float64 2D distance from (n, 2) world points to the footprint of ``box`` (0 inside)."""
    p = np.asarray(points, np.float64).reshape(-1, 2) - np.asarray(box.center[:2])
    c, s = np.cos(box.yaw), np.sin(box.yaw)
    lx, ly = np.abs(p[:, 0] * c + p[:, 1] * s), np.abs(-p[:, 0] * s + p[:, 1] * c)
    dx = np.maximum(lx - box.size[0] / 2, 0)
    dy = np.maximum(ly - box.size[1] / 2, 0)
    return np.hypot(dx, dy)


def point_polygon_distance(points: np.ndarray, polygon: np.ndarray) -> np.ndarray:
    """(n,) float64 2D distance from (n, 2) points to a convex (k, 2) counter-clockwise polygon (0 inside)."""
    p = np.asarray(points, np.float64).reshape(-1, 1, 2)
    a = np.asarray(polygon, np.float64).reshape(1, -1, 2)
    e = np.roll(a, -1, axis=1) - a
    t = np.clip(((p - a) * e).sum(-1) / np.maximum((e * e).sum(-1), 1e-18), 0.0, 1.0)
    d = np.linalg.norm(p - a - t[..., None] * e, axis=-1).min(1)
    inside = ((e[..., 0] * (p[..., 1] - a[..., 1]) - e[..., 1] * (p[..., 0] - a[..., 0])) >= 0).all(1)
    return np.where(inside, 0.0, d)
