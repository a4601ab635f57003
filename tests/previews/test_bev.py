"""The bird's-eye preview: each pixel shows the class of its highest point, and the PNG holds those pixels."""

from __future__ import annotations

import numpy as np
from PIL import Image

from generator.labels import class_table
from generator.previews.bev import MOVING_RGB, bev_image, write_bev


def painted_lowest_first(xyz, cls, extent_m, res_m):
    """Reference: every point painted in order of height (ties in input order), each over the ones before."""
    size = int(round(extent_m / res_m))
    img = np.zeros((size, size, 3), np.uint8)
    for i in sorted(range(len(xyz)), key=lambda i: (xyz[i, 2], i)):
        r = int(np.floor((extent_m / 2 - xyz[i, 0]) / res_m))
        c = int(np.floor((extent_m / 2 - xyz[i, 1]) / res_m))
        if 0 <= r < size and 0 <= c < size:
            img[r, c] = class_table().colors[cls[i]]
    return img


def test_each_pixel_shows_its_highest_point_and_the_later_of_two_at_one_height(rng):
    n = 4000
    xyz = np.column_stack([rng.uniform(-6, 6, n), rng.uniform(-6, 6, n), rng.integers(0, 4, n) * 0.5])  # many ties
    cls = rng.integers(0, len(class_table()), n).astype(np.uint8)
    img = np.asarray(bev_image(xyz.astype(np.float32), cls, extent_m=10.0, res_m=1.0, legend=False))
    ref = painted_lowest_first(xyz.astype(np.float32).astype(np.float64), cls, 10.0, 1.0)
    ref[5, 1:10], ref[1:10, 5] = 255, 255  # the sensor's cross
    assert np.array_equal(img, ref)


def test_moving_points_are_drawn_over_everything_and_the_png_keeps_the_pixels(tmp_path, rng):
    xyz = np.array([[1.05, 1.05, 0.0], [1.05, 1.05, 9.0], [-2.05, 2.05, 0.0]], np.float32)
    cls = np.array([1, 2, 3], np.uint8)
    moving = np.array([1, 0, 0], np.uint8)
    img = np.asarray(bev_image(xyz, cls, extent_m=10.0, res_m=0.1, legend=False, moving=moving))
    r, c = int(np.floor((5 - 1.05) / 0.1)), int(np.floor((5 - 1.05) / 0.1))
    assert np.all(img[r - 1:r + 2, c - 1:c + 2] == MOVING_RGB)  # the low mover beats the high point above it
    r3, c3 = int(np.floor((5 + 2.05) / 0.1)), int(np.floor((5 - 2.05) / 0.1))
    assert np.array_equal(img[r3, c3], class_table().colors[3])
    write_bev(tmp_path / "b.png", xyz, cls, moving=moving, title="t")
    assert np.array_equal(np.asarray(Image.open(tmp_path / "b.png").convert("RGB")),
                          np.asarray(bev_image(xyz, cls, moving=moving, title="t")))
