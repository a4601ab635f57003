"""The ring fit: ring and column of urbangen's own points recovered exactly from their positions."""

from __future__ import annotations

import numpy as np
import pytest

from generator.gap.rings import RingModel
from generator.lidar.scan import Scanner
from generator.lidar.sensors import load_preset
from generator.world.rig import Rig


@pytest.fixture(scope="module")
def sweep(test_spec, test_scene):
    sensor = load_preset("hdl64e")
    with Scanner(test_scene, sensor, threads=2) as sc:
        return sensor, sc.sweep(Rig.from_spec(test_spec, test_scene), 0.0, True)


def test_ring_and_column_of_every_point_are_recovered_from_its_position(sweep):
    sensor, scan = sweep
    fit = RingModel(sensor).fit(scan.xyz)
    assert len(scan.points) > 50_000
    assert np.array_equal(fit.ring, scan.points["ring"])
    assert np.array_equal(fit.column, scan.points["column"])
    assert np.abs(fit.vertical_m).max() < 1e-4  # on the cone of its laser to float precision
    np.testing.assert_allclose(fit.range_m, np.linalg.norm(scan.xyz, axis=1), rtol=1e-6)


def test_jitter_moves_points_off_their_cone(sweep):
    """Seed 002's +-5 cm jitter: the vertical miss spreads to centimetres (what ring_fit_vertical measures)."""
    sensor, scan = sweep
    xyz = scan.xyz + np.random.default_rng(0).uniform(-0.05, 0.05, scan.xyz.shape)
    fit = RingModel(sensor).fit(xyz)
    assert 0.01 < np.median(np.abs(fit.vertical_m)) < 0.05
    near = np.linalg.norm(scan.xyz, axis=1) < 10  # within 10 m the jitter exceeds half the laser spacing
    assert (fit.ring[near] != scan.points["ring"][near]).mean() > 0.2


def test_every_laser_and_column_from_the_driver_equations_at_any_range():
    """Points made with the Velodyne driver's equations, 0.9-120 m (the 6 cm between the HDL-64E's two
    laser blocks is worth several lasers at the minimum range)."""
    sensor = load_preset("hdl64e")
    rng = np.random.default_rng(3)
    n = 200_000
    laser = rng.integers(0, sensor.n_lasers, n)
    col = rng.integers(0, sensor.azimuth_steps, n)
    d = np.exp(rng.uniform(np.log(0.9), np.log(120.0), n))
    v, vo, h = sensor.elevation[laser], sensor.vert_offset[laser], sensor.horiz_offset[laser]
    phi = sensor.column_azimuth()[col] + sensor.rot_correction[laser]
    a = d * np.cos(v) - vo * np.sin(v)
    xyz = np.stack([a * np.cos(phi) - h * np.sin(phi), a * np.sin(phi) + h * np.cos(phi),
                    d * np.sin(v) + vo * np.cos(v)], -1)
    fit = RingModel(sensor).fit(xyz)
    assert np.array_equal(fit.ring, sensor.ring[laser])
    assert np.array_equal(fit.column, col)
