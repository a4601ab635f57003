"""Seed 002 domain-gap processing: exact removal fraction, jitter bounds, constant intensity, switches, seeds,
metadata."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from generator.errors import UserError
from generator.formats import semantickitti as sk
from generator.geometry import box, rect
from generator.jobs.lidar_sequence import SequenceOptions, write_sequence
from generator.lidar.scan import POINT_DTYPE
from generator.rng import stream
from generator.scan_effects.domain_gap import PRESETS, DomainGap, apply_domain_gap, apply_to_points, preset
from kits.scene_kit import scene_of


def cloud(n=20_000, seed=0):
    g = np.random.default_rng(seed)
    return g.uniform(-50, 50, (n, 3)).astype(np.float32), g.uniform(0, 1, n).astype(np.float32)


def test_seed002_preset_is_the_paper():
    # the paper's intensity 1 on a 0-255 scale, on SemanticKITTI's [0, 1] scale
    assert preset("seed002") == DomainGap(dropout=0.10, jitter_m=0.05, constant_intensity=1.0 / 255.0)
    with pytest.raises(UserError, match="unknown domain-gap preset 'x'; known: seed002, none"):
        preset("x")


@pytest.mark.parametrize("n", [1, 9, 10, 12_345, 20_000])
def test_removal_fraction_is_exact_and_order_kept(n):
    xyz, rem = cloud(n)
    keep, out, r2, info = apply_domain_gap(xyz, rem, PRESETS["seed002"], np.random.default_rng(1))
    assert len(keep) == n - round(0.1 * n) == len(out) == len(r2)
    assert info["removed"] == round(0.1 * n) and info["points_in"] == n
    assert np.all(np.diff(keep) > 0)  # original order


def test_jitter_is_uniform_within_bounds_on_every_axis():
    xyz, rem = cloud()
    keep, out, _, _ = apply_domain_gap(xyz, rem, DomainGap(jitter_m=0.05), np.random.default_rng(2))
    d = out.astype(np.float64) - xyz[keep]
    assert len(keep) == len(xyz)
    assert np.abs(d).max() <= 0.05 + 1e-5  # float32 rounding of |coords| <= 50 m
    for axis in range(3):
        assert abs(d[:, axis].mean()) < 0.002 and abs(d[:, axis].std() - 0.05 / np.sqrt(3)) < 0.001
        assert d[:, axis].max() > 0.049 and d[:, axis].min() < -0.049


def test_each_part_switches_off():
    xyz, rem = cloud(1000)
    keep, out, r2, _ = apply_domain_gap(xyz, rem, DomainGap(), np.random.default_rng(0))
    assert np.array_equal(out, xyz) and np.array_equal(r2, rem) and len(keep) == 1000
    _, out, r2, _ = apply_domain_gap(xyz, rem, DomainGap(constant_intensity=1.0), np.random.default_rng(0))
    assert np.array_equal(out, xyz) and np.all(r2 == 1.0)
    keep, out, r2, _ = apply_domain_gap(xyz, rem, DomainGap(dropout=0.3), np.random.default_rng(0))
    assert len(keep) == 700 and np.array_equal(out, xyz[keep]) and np.array_equal(r2, rem[keep])


def test_seeded_by_stream():
    xyz, rem = cloud(5000)
    a = apply_domain_gap(xyz, rem, PRESETS["seed002"], stream(3, "frame", 4, "lidar_domain_gap"))
    b = apply_domain_gap(xyz, rem, PRESETS["seed002"], stream(3, "frame", 4, "lidar_domain_gap"))
    c = apply_domain_gap(xyz, rem, PRESETS["seed002"], stream(3, "frame", 5, "lidar_domain_gap"))
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
    assert not np.array_equal(a[0], c[0])


@pytest.mark.parametrize("kw, message", [
    ({"dropout": 1.0}, "dropout must be in [0, 1)"),
    ({"jitter_m": -0.1}, "jitter_m must be in [0, 1]"),
    ({"constant_intensity": 2.0}, "constant_intensity must be in [0, 1]"),
])
def test_bad_parameters(kw, message):
    with pytest.raises(UserError) as e:
        DomainGap(**kw)
    assert message in str(e.value)


def test_structured_points_keep_their_labels():
    pts = np.zeros(1000, POINT_DTYPE)
    pts["x"] = np.arange(1000)
    pts["class"] = np.arange(1000) % 20
    pts["instance"] = np.arange(1000)
    out, rem, _ = apply_to_points(pts, np.zeros(1000, np.float32), PRESETS["seed002"], np.random.default_rng(0))
    assert len(out) == 900 and np.all(rem == np.float32(1.0 / 255.0))
    src = out["instance"]  # the instance id says which input point each output is
    assert np.all(np.abs(out["x"] - pts["x"][src]) <= 0.05 + 1e-4)
    assert np.array_equal(out["class"], pts["class"][src])


def test_sequence_applies_the_gap_and_records_it(test_spec, tmp_path):
    scene = scene_of([("ground", rect(-100, -100, 100, 100, 0.0, "road", "asphalt"), 0),
                      ("wall", box((2.0, 20.0, 8.0), "building", "facade_brick", center=(15.0, 0.0, 4.0)), 5)])
    spec = dataclasses.replace(test_spec, lidar=dataclasses.replace(
        test_spec.lidar, domain_gap=dataclasses.replace(test_spec.lidar.domain_gap, enabled=True)))
    meta = write_sequence(scene, spec, tmp_path,
                          SequenceOptions(frames=2, threads=1, bev=False), progress=False)
    assert meta["processing"]["domain_gap"]["dropout"] == 0.1 and meta["processing"]["domain_gap"]["jitter_m"] == 0.05
    for rec, scan_meta in zip(sk.Sequence(tmp_path, 0), meta["scans"], strict=False):
        cast = scan_meta["points_cast"]
        assert scan_meta["domain_gap"]["removed"] == round(0.1 * cast)
        assert len(rec.points) == cast - round(0.1 * cast) == scan_meta["points"]
        assert np.all(rec.points[:, 3] == np.float32(1.0 / 255.0)) and len(rec.semantic) == len(rec.points)
    on_disk = json.loads((tmp_path / "sequences" / "00" / "lidar_meta.json").read_text())
    assert on_disk["scans"][0]["domain_gap"]["constant_intensity"] == 1.0 / 255.0
    assert "1/255" in on_disk["scans"][0]["domain_gap"]["scale_note"]


@pytest.mark.parametrize("extra, message", [
    (["--dropout", "1.5"], "--dropout: must be a number in [0, 1), got '1.5'"),
    (["--gap-intensity", "abc"], "--gap-intensity: must be a number in [0, 1] or 'none', got 'abc'"),
    (["--domain-gap", "off", "--dropout", "0.2"], "--domain-gap off contradicts"),
    (["--constant-intensity", "3"], "--constant-intensity: must be a number in [0, 1], got '3'"),
])
def test_lidar_command_processing_options_errors(root, tmp_path, capsys, monkeypatch, extra, message):
    import generator.cli as cli
    monkeypatch.setattr(cli, "COMMANDS", ["lidar"])
    out = tmp_path / "ds"
    rc = cli.main(["lidar", str(root / "scenes" / "test_town.json"), "--out", str(out), "--frames", "1", *extra])
    err = capsys.readouterr().err
    assert rc == 2 and message in err and err.count("\n") == 1, err
    assert not out.exists()


def test_command_line_options_reach_the_spec(test_spec):
    import argparse

    from generator.commands.intensity import add_processing_args, spec_with_processing_args
    p = argparse.ArgumentParser()
    add_processing_args(p, weather=True)
    spec = spec_with_processing_args(test_spec, p.parse_args(["--intensity", "hybrid", "--domain-gap", "seed002",
                                                              "--jitter-m", "0.02", "--lidar-weather", "on"]))
    g = spec.lidar.domain_gap
    assert spec.lidar.intensity_model == "hybrid" and spec.lidar.weather.enabled is True
    assert (g.enabled, g.dropout, g.jitter_m, g.constant_intensity) == (True, 0.1, 0.02, 1.0 / 255.0)
    assert spec.spec_hash != test_spec.spec_hash
    same = spec_with_processing_args(test_spec, p.parse_args([]))
    assert same == test_spec  # no options: the spec (and its hash) unchanged
