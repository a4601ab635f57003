"""The route keep-out: objects keep ``limit`` metres (2D) from every route sample.

Distances from route samples to an object's footprint: an oriented box
(:func:`generator.geometry.boxes.point_box_distance`) or, for the parallelogram a skewed town makes
of a shaped object's box, a convex polygon (:func:`generator.geometry.boxes.point_polygon_distance`).
Frames: whichever frame the samples are in (grid or world), metres.
"""

from __future__ import annotations

import numpy as np

from generator.geometry.boxes import OrientedBox, point_box_distance, point_polygon_distance


class Keepout:
    """Route samples every 25 cm; objects must keep ``limit`` metres (2D) away from all of them."""

    def __init__(self, samples_xy: np.ndarray, limit: float):
        self.points = np.asarray(samples_xy, np.float64).reshape(-1, 2)
        self.limit = float(limit)
        from scipy.spatial import cKDTree  # imported on first use (scipy.spatial: ~0.4 s)

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
