"""KITTI box overlaps: 2D IoU, bird's-eye and 3D IoU with exact rectangle clipping."""

from __future__ import annotations

import numpy as np
import pytest

from generator.stats.box_overlap import bev_iou, box3d_iou, convex_intersection_area, ground_rectangles, image_iou


def _box(x, z, length=4.0, width=2.0, h=1.5, ry=0.0, y=1.6):
    return {"location": np.array([[x, y, z]]), "dimensions": np.array([[h, width, length]]),
            "rotation_y": np.array([ry])}


def test_image_iou_and_the_dontcare_criterion():
    a, b = np.array([[0, 0, 10, 10.0]]), np.array([[5, 0, 15, 10.0], [20, 20, 30, 30.0]])
    np.testing.assert_allclose(image_iou(a, b), [[50 / 150, 0.0]])
    np.testing.assert_allclose(image_iou(a, b, criterion=0), [[0.5, 0.0]])


def test_a_box_moved_along_its_length():
    # same size and heading, moved 1 m along the 4 m length: (3 x 2) / (2 * 8 - 6)
    assert bev_iou(_box(0, 10), _box(1.0, 10))[0, 0] == pytest.approx(6 / 10)
    assert box3d_iou(_box(0, 10), _box(1.0, 10))[0, 0] == pytest.approx(6 / 10)
    # and lifted by half its height: the 3D overlap halves its intersection
    assert box3d_iou(_box(0, 10), _box(0, 10, y=1.6 - 0.75))[0, 0] == pytest.approx(0.5 / 1.5)


def test_a_square_turned_by_45_degrees():
    # a 2 x 2 square and the same turned 45 degrees: the regular octagon, 8 (sqrt 2 - 1)
    inter = convex_intersection_area(ground_rectangles(np.zeros((1, 2)), np.array([[2.0, 2.0]]), np.zeros(1)),
                                     ground_rectangles(np.zeros((1, 2)), np.array([[2.0, 2.0]]), np.array([np.pi / 4])))
    assert inter[0] == pytest.approx(8 * (np.sqrt(2) - 1))


def test_random_rectangles_match_an_independent_polygon_clipper(rng):
    shapely = pytest.importorskip("shapely.geometry")
    a = ground_rectangles(rng.uniform(-2, 2, (300, 2)), rng.uniform(0.5, 4, (300, 2)), rng.uniform(-3, 3, 300))
    b = ground_rectangles(rng.uniform(-2, 2, (300, 2)), rng.uniform(0.5, 4, (300, 2)), rng.uniform(-3, 3, 300))
    ref = [shapely.Polygon(p).intersection(shapely.Polygon(q)).area for p, q in zip(a, b, strict=True)]
    np.testing.assert_allclose(convex_intersection_area(a, b), ref, atol=1e-9)
