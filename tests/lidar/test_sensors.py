"""Sensor tables: the HDL-64E equals the reference calibration; the driver's geometry; validation."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from generator.errors import SpecError
from generator.lidar.sensors import load_preset, load_sensor, preset_names, sensor_for_spec
from generator.spec import load_spec
from kits.paths import SHARED

REFERENCE = SHARED / "reference" / "velodyne_hdl64e_s3_calibration.yaml"


@pytest.fixture(scope="module")
def reference():
    if not REFERENCE.is_file():
        pytest.skip("reference calibration not available")
    return yaml.safe_load(REFERENCE.read_text())["lasers"]


def test_hdl64e_equals_reference_calibration(reference):
    s = load_preset("hdl64e")
    assert s.n_lasers == 64 and s.rotation_hz == 10 and s.azimuth_steps == 2083
    assert (s.min_range_m, s.max_range_m) == (0.9, 120.0)
    for key, ours in (("vert_correction", s.elevation), ("rot_correction", s.rot_correction),
                      ("vert_offset_correction", s.vert_offset), ("horiz_offset_correction", s.horiz_offset),
                      ("dist_correction", s.dist_correction)):
        ref = np.array([r[key] for r in reference])
        np.testing.assert_allclose(ours, ref, rtol=0, atol=1e-9, err_msg=key)
    assert s.laser_id.tolist() == [r["laser_id"] for r in reference]  # original laser order kept


def test_rings_sorted_by_elevation_highest_first():
    for name in preset_names():
        s = load_preset(name)
        assert sorted(s.ring.tolist()) == list(range(s.n_lasers))
        elev = s.elevation[s.by_ring]
        assert np.all(np.diff(elev) < 0), name  # ring 0 highest, strictly down


def test_uniform_presets():
    h32, v16 = load_preset("hdl32e"), load_preset("vlp16")
    np.testing.assert_allclose(np.degrees(h32.elevation[h32.by_ring][[0, -1]]), [10.67, -30.67], atol=1e-12)
    np.testing.assert_allclose(np.diff(np.degrees(v16.elevation[v16.by_ring])), -2.0, atol=1e-12)
    assert h32.n_lasers == 32 and v16.n_lasers == 16


def _driver_point(d, psi, v, rc, vo, h):
    """velodyne_pointcloud RawData::unpack (HDL-64E, no distance corrections), written as the driver does:
    rotation angle clockwise from the device's +y, then x_ros = y, y_ros = -x."""
    theta = -psi  # device encoder angle, clockwise
    cos_rot = np.cos(theta) * np.cos(rc) + np.sin(theta) * np.sin(rc)  # cos(theta - rc)
    sin_rot = np.sin(theta) * np.cos(rc) - np.cos(theta) * np.sin(rc)
    xy = d * np.cos(v) - vo * np.sin(v)
    xx = xy * sin_rot - h * cos_rot
    yy = xy * cos_rot + h * sin_rot
    z = d * np.sin(v) + vo * np.cos(v)
    # device frame x right, y forward -> ROS x forward (device y), y left (-device x)
    return np.stack([yy, -xx, z], -1)


def test_local_rays_follow_the_velodyne_driver(rng):
    s = load_preset("hdl64e")
    origins, dirs, azimuth = s.local_rays()
    order = s.by_ring
    psi = s.column_azimuth()
    cols = rng.integers(0, s.azimuth_steps, 300)
    rings = rng.integers(0, s.n_lasers, 300)
    d = rng.uniform(1, 100, 300)
    li = order[rings]
    ours = origins[cols, rings] + d[:, None] * dirs[cols, rings]
    ref = _driver_point(d, psi[cols], s.elevation[li], s.rot_correction[li], s.vert_offset[li], s.horiz_offset[li])
    np.testing.assert_allclose(ours, ref, atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(dirs, axis=-1), 1.0, atol=1e-12)


def test_sweep_timing_and_direction():
    s = load_preset("hdl64e")
    t = s.column_time()
    assert t[0] == 0 and abs(t[-1] - 0.1 * (s.azimuth_steps - 1) / s.azimuth_steps) < 1e-12
    psi = s.column_azimuth()
    assert abs(psi[0] - np.pi) < 1e-12 and psi[1] < psi[0]  # starts straight back, spins clockwise


def _write(tmp_path: Path, name: str, text: str) -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


@pytest.mark.parametrize("text, field", [
    ("name: x\nrotation_hz: 10\nazimuth_steps: 100\nrange_m: [1, 50]\nlasers:\n  - {laser_id: 0}\n",
     "lasers[0].vert_correction"),
    ("name: x\nrotation_hz: 0\nazimuth_steps: 100\nrange_m: [1, 50]\nuniform: {beams: 4, elevation_deg: [-5, 5]}\n",
     "rotation_hz"),
    ("name: x\nrotation_hz: 10\nazimuth_steps: 100\nrange_m: [50, 1]\nuniform: {beams: 4, elevation_deg: [-5, 5]}\n",
     "range_m"),
    ("name: x\nrotation_hz: 10\nazimuth_steps: 100\nrange_m: [1, 50]\n", "lasers"),
    ("name: x\nrotation_hz: 10\nazimuth_steps: 100\nrange_m: [1, 50]\nuniform: {beams: 4, elevation_deg: [-5, 5]}\n"
     "laser_count: 3\n", "laser_count"),
])
def test_bad_sensor_file_is_one_line_naming_file_and_field(tmp_path, text, field):
    p = _write(tmp_path, "bad.yaml", text)
    with pytest.raises(SpecError) as e:
        load_sensor(p)
    msg = str(e.value)
    assert "\n" not in msg and str(p) in msg and e.value.field == field, msg


def test_user_sensor_file_relative_to_spec(tmp_path):
    _write(tmp_path, "my_lidar.yaml", "name: mine\nrotation_hz: 20\nazimuth_steps: 360\nrange_m: [0.5, 60]\n"
                                       "uniform: {beams: 8, elevation_deg: [-10, 4]}\n")
    spec_path = _write(tmp_path, "spec.json", json.dumps({"name": "t", "seed": 1,
                                                          "sensors": {"lidar": {"sensor_file": "my_lidar.yaml"}}}))
    s = sensor_for_spec(load_spec(spec_path))
    assert s.name == "mine" and s.n_lasers == 8 and s.period_s == 0.05
    np.testing.assert_allclose(np.degrees(s.elevation[s.by_ring][[0, -1]]), [4, -10])


def test_missing_user_sensor_file_names_it(tmp_path):
    spec_path = _write(tmp_path, "spec.json", json.dumps({"name": "t", "seed": 1,
                                                          "sensors": {"lidar": {"sensor_file": "nope.yaml"}}}))
    with pytest.raises(SpecError, match="nope.yaml: file not found"):
        sensor_for_spec(load_spec(spec_path))


def test_unknown_preset_names_the_spec_field(tmp_path):
    spec_path = _write(tmp_path, "spec.json", json.dumps({"name": "t", "seed": 1,
                                                          "sensors": {"lidar": {"preset": "hdl128"}}}))
    with pytest.raises(SpecError) as e:
        sensor_for_spec(load_spec(spec_path))
    assert e.value.field == "sensors.lidar.preset" and "hdl64e" in str(e.value) and str(spec_path) in str(e.value)
