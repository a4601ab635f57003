"""LiDAR weather: fog thins far points and dims intensity, soft returns, rain noise, wet ground, tied to the
frame draw."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from generator.formats import semantickitti as sk
from generator.geometry import box, rect
from generator.jobs.lidar_sequence import SequenceOptions, write_sequence
from generator.labels import class_table
from generator.lidar.scan import POINT_DTYPE
from generator.materials import material_table
from generator.remission.models import constant
from generator.scan_effects.pipeline import ScanProcessing, process_scan, processing_for_spec
from generator.scan_effects.weather import (
    LidarWeatherParams,
    apply_lidar_weather,
    extinction_per_m,
    frame_weather,
    weather_config,
)
from generator.weather import KOSCHMIEDER, Weather, draw_weather, lidar_combination
from kits.scene_kit import scene_of

PARAMS = LidarWeatherParams(1e-5, 0.9)


def wall_points(n=60_000, native="building", material="facade_concrete", seed=0, cos=None):
    """Points on surfaces at 3..120 m along random directions (sensor frame)."""
    g = np.random.default_rng(seed)
    d = g.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    r = g.uniform(3, 120, n)
    p = np.zeros(n, POINT_DTYPE)
    p["x"], p["y"], p["z"] = (d * r[:, None]).T
    p["range"] = r
    p["cos_incidence"] = g.uniform(0.3, 1.0, n) if cos is None else cos
    p["class"] = class_table().id(native)
    p["material"] = material_table().id(material)
    p["instance"] = 7
    p["column"] = np.arange(n)  # unique per point: says which input a processed point came from
    return p


def fog(v):
    return Weather("fog", 0.0, 0.0, float(v), KOSCHMIEDER / v, None)


def test_more_fog_fewer_far_points_and_lower_intensity():
    pts = wall_points()
    rem = np.full(len(pts), 0.5, np.float32)
    far, mean_i = [], []
    for v in (1e9, 250.0, 120.0, 60.0, 40.0):
        w = Weather("clear", 0.0, 0.0) if v == 1e9 else fog(v)
        out, r, info = apply_lidar_weather(pts, rem, w, PARAMS, np.random.default_rng(0))
        hard = out["class"] != 0
        far.append(int((out["range"][hard] > 40).sum()))
        mean_i.append(float(r[hard].mean()))
        assert r.min() >= 0 and r.max() <= 1
    assert far[0] == int((pts["range"] > 40).sum())  # clear air keeps these (threshold 1e-5)
    assert all(a > b for a, b in zip(far, far[1:], strict=False)), far
    assert all(a > b for a, b in zip(mean_i, mean_i[1:], strict=False)), mean_i
    assert far[-1] < 0.02 * far[0]  # 40 m visibility: almost nothing beyond 40 m


def test_fog_alpha_is_the_image_beta_and_intensity_follows_two_way_loss():
    pts = wall_points(2000, cos=1.0)
    pts["range"] = 10.0
    w = fog(100.0)
    out, r, info = apply_lidar_weather(pts, np.full(2000, 0.5, np.float32), w, PARAMS, np.random.default_rng(0))
    assert info["alpha_fog_per_m"] == pytest.approx(3.912 / 100.0) and info["alpha_rain_per_m"] == 0.0
    hard = out["class"] != 0
    assert np.allclose(r[hard], 0.5 * np.exp(-2 * 0.03912 * 10.0), atol=1e-6)


def test_fog_soft_returns_are_near_unlabelled_and_in_front_of_their_target():
    pts = wall_points()
    w = fog(40.0)
    out, r, info = apply_lidar_weather(pts, np.full(len(pts), 0.5, np.float32), w, PARAMS, np.random.default_rng(3))
    soft = out["class"] == 0
    n_soft = int(soft.sum())
    cfg = weather_config()["fog"]
    expected = len(pts) * min(cfg["soft_return_max"], cfg["soft_return_per_beta_m"] * w.beta_per_m)
    assert n_soft == info["fog_soft_returns"] and 0.5 * expected < n_soft <= expected * 1.2
    assert np.all(out["instance"][soft] == 0) and np.all(r[soft] <= cfg["soft_return_intensity_max"])
    assert out["range"][soft].min() >= 0.9 and np.percentile(out["range"][soft], 95) < 12.0
    # each soft return sits on its ray, in front of the surface it hides
    src = pts[out["column"][soft]]
    d_out = np.stack([out["x"], out["y"], out["z"]], -1)[soft]
    d_src = np.stack([src["x"], src["y"], src["z"]], -1)
    assert np.allclose(d_out / np.linalg.norm(d_out, axis=1, keepdims=True),
                       d_src / np.linalg.norm(d_src, axis=1, keepdims=True), atol=1e-5)
    assert np.allclose(np.linalg.norm(d_out, axis=1), out["range"][soft], atol=1e-3)
    assert np.all(out["range"][soft] < src["range"])
    clear, _, info_c = apply_lidar_weather(pts, np.full(len(pts), 0.5, np.float32), Weather("clear", 0.0, 0.0), PARAMS,
                                           np.random.default_rng(3))
    assert info_c["fog_soft_returns"] == 0 and np.all(clear["class"] != 0)


def test_rain_extinction_units_and_range_noise():
    w = Weather("rain", 0.0, 0.0, rain_rate_mmh=20.0)
    a_fog, a_rain = extinction_per_m(w)
    assert a_fog == 0 and a_rain == pytest.approx(0.01 * 20 ** 0.6 / 1000.0)  # 1/km -> 1/m
    n = 40_000
    pts = wall_points(n, cos=1.0)
    d = np.stack([pts["x"], pts["y"], pts["z"]], -1) / pts["range"][:, None]
    pts["range"] = 50.0
    pts["x"], pts["y"], pts["z"] = (d * 50.0).T
    out, _, info = apply_lidar_weather(pts, np.full(n, 0.5, np.float32), w, PARAMS, np.random.default_rng(5))
    assert len(out) == n  # negligible rain extinction: nothing lost at 50 m for a concrete wall
    sigma = 0.02 * 50.0 * (1 - np.exp(-20.0)) ** 2
    dr = out["range"].astype(np.float64) - 50.0
    assert abs(dr.std() - sigma) < 0.03 * sigma and abs(dr.mean()) < 4 * sigma / np.sqrt(n)
    xyz = np.stack([out["x"], out["y"], out["z"]], -1)
    assert np.allclose(xyz / np.linalg.norm(xyz, axis=1, keepdims=True), d, atol=1e-5)  # moved along the beam
    assert np.allclose(np.linalg.norm(xyz, axis=1), out["range"], atol=1e-3)
    assert info["range_noise_sigma_m_at_10m"] == pytest.approx(0.2 * (1 - np.exp(-20.0)) ** 2)


def test_wet_ground_returns_weaker_and_more_often_lost():
    n = 50_000
    road = wall_points(n, native="road", material="asphalt", cos=0.2)
    road["range"] = 10.0
    wall = wall_points(n, native="building", material="facade_concrete", cos=0.2)
    wall["range"] = 10.0
    w = Weather("wet", 0.9, 1.0)
    rem = np.full(n, 0.5, np.float32)
    out_r, r_r, info_r = apply_lidar_weather(road, rem, w, PARAMS, np.random.default_rng(1))
    out_w, r_w, info_w = apply_lidar_weather(wall, rem, w, PARAMS, np.random.default_rng(1))
    cfg = weather_config()["wet"]
    assert len(out_w) == n and np.allclose(r_w, 0.5)
    assert np.allclose(r_r, 0.5 * (1 - 0.9 * (1 - cfg["residual_power"])), atol=1e-6)
    lost = 1 - len(out_r) / n
    p = 0.9 * cfg["dropout_max"] * 0.8
    assert abs(lost - p) < 5 * np.sqrt(p * (1 - p) / n) and info_r["lost_wet_ground"] == n - len(out_r)


def test_scan_shares_the_frame_weather_draw(test_spec):
    spec = dataclasses.replace(test_spec, lidar=dataclasses.replace(
        test_spec.lidar, weather=dataclasses.replace(test_spec.lidar.weather, enabled=True)))
    proc = processing_for_spec(spec)
    assert proc.weather is not None and processing_for_spec(test_spec).weather is None  # auto = off for lidar
    assert processing_for_spec(test_spec, weather_default=True).weather is not None
    pts = wall_points(5000)
    for k in (2, 4, 10):
        tod, kind = lidar_combination(k)
        assert frame_weather(spec, k) == (tod, draw_weather(spec, k, kind))
        out, rem, rec = process_scan(pts, proc, spec, k)
        w = draw_weather(spec, k, kind)
        assert rec["weather"]["kind"] == kind and rec["weather"]["time_of_day"] == tod
        assert rec["weather"]["visibility_m"] == w.visibility_m and rec["weather"]["rain_rate_mmh"] == w.rain_rate_mmh
        out2, rem2, _ = process_scan(pts, proc, spec, k)
        assert np.array_equal(out, out2) and np.array_equal(rem, rem2)  # seeded by the frame's stream


def test_sequence_with_weather_records_it_per_scan(test_spec, tmp_path):
    scene = scene_of([("ground", rect(-150, -150, 150, 150, 0.0, "road", "asphalt"), 0),
                      ("wall", box((2.0, 40.0, 10.0), "building", "facade_brick", center=(60.0, 0.0, 5.0)), 5)])
    # the ideal sensor: the weather's own detection test (the physical sensor detects in the scanner)
    lidar = dataclasses.replace(test_spec.sensors.lidar, returns="ideal")
    spec = dataclasses.replace(test_spec, lidar=dataclasses.replace(test_spec.lidar, intensity_model="physical"),
                               sensors=dataclasses.replace(test_spec.sensors, lidar=lidar))
    meta = write_sequence(scene, spec, tmp_path, SequenceOptions(frames=4, threads=1, bev=False, weather=True),
                          progress=False)
    kinds = [s["weather"]["kind"] for s in meta["scans"]]
    assert kinds == [lidar_combination(k)[1] for k in range(4)] == ["clear", "clear", "fog", "fog"]
    on_disk = json.loads((tmp_path / "sequences" / "00" / "lidar_meta.json").read_text())
    assert on_disk["processing"]["weather"]["detection_threshold"] == 1e-5
    assert on_disk["processing"]["intensity"]["model"] == "physical"
    for rec, s in zip(sk.Sequence(tmp_path, 0), meta["scans"], strict=False):
        assert len(rec.points) == s["points"] == s["weather"]["points_out"]
        soft = s["weather"]["fog_soft_returns"]
        assert (rec.semantic == 0).sum() == soft and (soft > 0) == (s["weather"]["kind"] == "fog")
        assert 0 <= rec.points[:, 3].min() and rec.points[:, 3].max() <= 1


def test_weather_off_by_default_keeps_scans_unchanged(test_spec):
    pts = wall_points(3000)
    proc = ScanProcessing(constant(0.5))
    out, rem, rec = process_scan(pts, proc, test_spec, 3)
    assert np.array_equal(out, pts) and np.all(rem == 0.5) and rec["weather"] is None and rec["domain_gap"] is None
