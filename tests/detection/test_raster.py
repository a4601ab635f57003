"""Rasterising a thing's own triangles: pixel-centre sampling, near-plane clipping, truncation."""

from __future__ import annotations

import numpy as np
import pytest

from generator.detection.raster import NEAR_M, clip_near, coverage_outside, footprint, rasterise

K = np.array([[10.0, 0.0, 0.0], [0.0, 10.0, 0.0], [0.0, 0.0, 1.0]])


def _square(x0, y0, x1, y1, z=1.0):
    a, b, c, d = [x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]
    return np.array([[a, b, c], [a, c, d]], np.float64)


def test_a_square_covers_exactly_the_pixel_centres_inside_it():
    uv = np.array([[[2, 3], [12, 3], [12, 13]], [[2, 3], [12, 13], [2, 13]]], float)
    m = rasterise(uv, 20, 20)
    assert m.sum() == 100 and m[3:13, 2:12].all()
    # both windings, and a grid offset by half a pixel / supersampled
    assert rasterise(uv[:, ::-1], 20, 20).sum() == 100
    assert rasterise(uv, 40, 40, step=0.5).sum() == 400


def test_the_footprint_votes_like_the_label_pass():
    tri = _square(0.0, 0.0, 0.54, 1.0)          # u in [0, 5.4]: the 6th column is 40 % covered
    assert footprint(tri, K, 10, 10)[0].sum() == 50      # centres at 0.5..4.5 only
    assert footprint(tri, K, 10, 10, supersample=3)[0].sum() == 50   # 1 of 3 sub-columns: no majority
    assert footprint(_square(0.0, 0.0, 0.57, 1.0), K, 10, 10, supersample=3)[0].sum() == 60  # 2 of 3
    mask, origin = footprint(_square(0.3, 0.2, 0.6, 0.5), K, 10, 10)   # a window round it: pixels 3..5
    assert origin == (3, 2) and mask.shape == (3, 3) and mask.all()


def test_near_plane_clipping_keeps_what_is_in_front():
    one_in_front = np.array([[[0, 0, 1.0], [1, 0, -2.0], [0, 1, -2.0]]])
    two_in_front = np.array([[[0, 0, -1.0], [1, 0, 2.0], [0, 1, 2.0]]])
    a, b = clip_near(one_in_front), clip_near(two_in_front)
    assert a.shape == (1, 3, 3) and b.shape == (2, 3, 3)
    assert (a[..., 2] >= NEAR_M - 1e-12).all() and (b[..., 2] >= NEAR_M - 1e-12).all()
    behind = one_in_front.copy()
    behind[..., 2] = -1.0
    assert len(clip_near(behind)) == 0


@pytest.mark.parametrize("x0, expected", [(0.0, 0.0), (-0.5, 0.5), (-0.8, 0.8), (-2.0, 1.0)])
def test_truncation_is_the_share_outside(x0, expected):
    assert coverage_outside(_square(x0, 0.0, x0 + 1.0, 1.0), K, 10, 10) == pytest.approx(expected, abs=1e-9)


def test_a_thing_crossing_the_camera_plane_is_mostly_outside():
    a, b, c, d = [-1, 0.1, 0.01], [1, 0.1, 0.01], [1, 0.1, 5.0], [-1, 0.1, 5.0]
    wall = np.array([[a, b, c], [a, c, d]])
    assert coverage_outside(wall, K, 10, 10) > 0.9
