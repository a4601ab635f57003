"""The compare window of ``gap``: which rays of a sensor lie in an azimuth and elevation range."""

from __future__ import annotations

import numpy as np
import pytest

from generator.errors import UserError
from generator.gap.rings import RingModel
from generator.gap.window import Window, parse_window
from generator.lidar.sensors import load_preset


@pytest.fixture(scope="module")
def model():
    return RingModel(load_preset("hdl64e"))


def test_the_whole_window_holds_every_ray(model):
    w = parse_window(None, None)
    assert w.whole and w.cells(model).all()


def test_a_kitti_camera_crop_holds_its_share_of_columns_and_the_beams_above_its_floor(model):
    w = parse_window("-40:40", "-14:90")
    cells = w.cells(model)
    elev = np.degrees(load_preset("hdl64e").elevation)
    kept_rings = np.flatnonzero(cells.any(1))
    assert len(kept_rings) == int((elev >= -14).sum())           # beams under the floor are never inside
    per_ring = cells[kept_rings].sum(1) / model.steps
    assert np.allclose(per_ring, 80 / 360, atol=2 / model.steps)  # 80 of 360 degrees, each laser its own offset


def test_a_column_of_the_window_is_where_that_rays_points_land(model):
    """Points cast straight along the rays at the window's edges fall in the cells the window names."""
    w = Window(-40.0, 40.0, -14.0, 90.0)
    cells = w.cells(model)
    az = np.radians(np.array([-39.0, 0.0, 39.0, 41.0, 179.0]))
    xyz = np.stack([20 * np.cos(az), 20 * np.sin(az), np.full(5, -1.5)], 1).astype(np.float32)
    fit = model.fit(xyz)
    assert cells[fit.ring, fit.column].tolist() == [True, True, True, False, False]


@pytest.mark.parametrize("az, el, field", [("40:-40", None, "--azimuth"), ("a:b", None, "--azimuth"),
                                           (None, "-100:0", "--elevation"), ("0:10:20", None, "--azimuth")])
def test_a_bad_range_names_its_option(az, el, field):
    with pytest.raises(UserError, match=field):
        parse_window(az, el)
