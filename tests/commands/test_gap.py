"""``urbangen gap``: seed 002 §3.2 measured on a raw sequence and its seed-002-processed twin."""

from __future__ import annotations

import json

import numpy as np
import pytest

from generator.cli import main
from generator.formats import semantickitti as sk
from generator.scan_effects.domain_gap import SEED002_INTENSITY

FRAMES = 4


@pytest.fixture(scope="module")
def pair(tmp_path_factory, root):
    """The test town's first 4 sweeps, raw and with seed 002's processing (10 % dropout, +-5 cm, intensity 1/255)."""
    base = tmp_path_factory.mktemp("gap")
    spec = str(root / "scenes" / "test_town.json")
    for name, extra in (("raw", []), ("seed002", ["--domain-gap", "seed002"])):
        assert main(["-q", "lidar", spec, "--out", str(base / name), "--frames", str(FRAMES), "--no-bev",
                     "--threads", "2", *extra]) == 0
    return base / "raw", base / "seed002"


def _gap(out, *datasets, extra=()) -> dict:
    assert main(["-q", "gap", *map(str, datasets), "--out", str(out), *extra]) == 0
    return json.loads((out / "gap.json").read_text())


def _distances(report: dict) -> dict:
    return {k: m["distance"]["values"] for k, m in report["metrics"].items() if "distance" in m}


def test_a_sequence_against_itself_is_0_everywhere(pair, tmp_path):
    raw, _ = pair
    rep = _gap(tmp_path / "self", raw, raw, extra=("--names", "a,b"))
    dist = _distances(rep)
    assert len(dist) == 10  # every metric measured (labels and instances present)
    assert all(v == {"a vs b": 0.0} for v in dist.values()), dist
    assert rep["objects_from"] == "instances"
    for name in ("gap.md", "gap.png", "gap_rays_lost_per_ring.png", "gap_intensity.png"):
        assert (tmp_path / "self" / name).stat().st_size > 1000


def test_seed002_processing_shows_as_the_three_differences_it_adds(pair, tmp_path):
    raw, processed = pair
    rep = _gap(tmp_path / "rp", raw, processed, extra=("--names", "raw,seed002"))
    d = {k: v["raw vs seed002"] for k, v in _distances(rep).items()}
    lost = rep["metrics"]["rays_lost_per_ring"]["curves"]
    kept = 1 - np.array(lost["raw"])
    # 1. rays lost: a 10 % dropout of the returns adds 0.1 x (1 - loss) per ring, on average over the rings
    assert d["rays_lost_per_ring"] == pytest.approx(0.1 * kept.mean(), rel=0.1)
    # ... at every range: near bins lose 10 % more of their rays (jittered points sharing a cell are not losses);
    # within 5 m more than that: a 5 cm jitter there moves a point by over a column (0.17 deg) and ring
    # (0.4 deg), out of its own cell, which then counts as lost (measured 0.15 at 0-5 m, 0.07-0.10 beyond)
    per_range = rep["metrics"]["rays_lost_per_range"]["curves"]
    added = np.array(per_range["seed002"][:6]) - np.array(per_range["raw"][:6])  # 0-30 m
    assert np.abs(added[1:] - 0.1).max() < 0.05 and 0.08 < added[0] < 0.25, added
    # the dropout is uniform in range: the range distribution of the points stays the same
    assert d["points_per_range"] < 0.02
    # 2. rings: +-5 cm jitter moves points centimetres off their cone and along their ring
    assert d["ring_fit_vertical"] > 0.01 and d["ring_regularity"] > 0.005
    # 3. intensity: W1 to a point mass at c is the mean distance to c
    rem = np.concatenate([sk.read_scan(p)[:, 3] for p in sorted((raw / "lidar/sequences/00/velodyne").glob("*.bin"))])
    assert d["intensity"] == pytest.approx(np.abs(rem - SEED002_INTENSITY).mean(), abs=0.01)
    assert d["class_mix"] < 0.01  # a uniform dropout leaves the mix


def test_a_third_dataset_and_pairwise(pair, tmp_path):
    raw, processed = pair
    rep = _gap(tmp_path / "three", raw, processed, raw, extra=("--names", "raw,seed002,raw2", "--pairwise"))
    assert rep["pairs"] == ["raw vs seed002", "raw vs raw2", "seed002 vs raw2"]
    d = _distances(rep)["intensity"]
    assert d["raw vs raw2"] == 0.0 and d["raw vs seed002"] == d["seed002 vs raw2"] > 0


def test_an_empty_real_folder_is_one_line_exit_2_and_nothing_written(pair, tmp_path, capsys):
    raw, _ = pair
    empty = tmp_path / "real"
    empty.mkdir()
    out = tmp_path / "report"
    assert main(["gap", str(raw), str(empty), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"REAL: {empty}: the folder is empty" in err[0]
    (empty / "sequences" / "00" / "velodyne").mkdir(parents=True)
    assert main(["gap", str(raw), str(empty), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "REAL:" in err[0] and "no scans" in err[0]
    assert not out.exists()


@pytest.fixture(scope="module")
def nus_labelled(nuscenes_traffic, traffic_detection_dataset, tmp_path_factory):
    from kits.nuscenes_lidarseg import with_lidarseg

    root, _ = traffic_detection_dataset
    return with_lidarseg(nuscenes_traffic, root, tmp_path_factory.mktemp("gapnus") / "nus")


def test_a_nuscenes_root_against_itself_is_0_and_says_its_sensor(nus_labelled, tmp_path):
    rep = _gap(tmp_path / "nus", nus_labelled, nus_labelled, extra=("--names", "a,b"))
    dist = _distances(rep)
    assert rep["objects_from"] == "boxes"  # sample annotations, counted in the sensor frame
    assert all(v == {"a vs b": 0.0} for v in dist.values()), dist
    assert len(dist) == 10
    assert [d["layout"] for d in rep["datasets"]] == ["nuscenes", "nuscenes"]
    assert rep["datasets"][0]["sensor"].endswith("hdl64e.yaml")  # our export: 64 rings


def test_a_lidarseg_of_the_wrong_length_is_one_line_exit_2_and_nothing_written(nus_labelled, tmp_path, capsys):
    import shutil

    bad = tmp_path / "bad"
    shutil.copytree(nus_labelled, bad)
    label = sorted((bad / "lidarseg").rglob("*_lidarseg.bin"))[0]
    label.write_bytes(label.read_bytes()[:-1])
    out = tmp_path / "report"
    assert main(["gap", str(nus_labelled), str(bad), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and label.name in err[0] and "lidarseg:" in err[0], err
    assert not out.exists()


def test_a_camera_crop_compared_within_its_window_is_its_scan(pair, tmp_path):
    """KITTI's velodyne_reduced: the raw sweeps cut to +-40 deg and -14 deg up, against the raw sweeps."""
    from generator.gap.rings import RingModel
    from generator.gap.window import Window
    from generator.lidar.sensors import load_preset

    raw, _ = pair
    cells = Window(-40.0, 40.0, -14.0, 90.0).cells(RingModel(load_preset("hdl64e")))
    crop = tmp_path / "crop" / "sequences" / "00" / "velodyne"
    crop.mkdir(parents=True)
    for p in sorted((raw / "lidar/sequences/00/velodyne").glob("*.bin")):
        scan = sk.read_scan(p)
        az = np.degrees(np.arctan2(scan[:, 1], scan[:, 0]))
        el = np.degrees(np.arctan2(scan[:, 2], np.hypot(scan[:, 0], scan[:, 1])))
        keep = (np.abs(az) <= 40) & (el >= -14.5)  # the points of the crop, by their own direction
        sk.write_scan(crop / p.name, scan[keep, :3], scan[keep, 3])
    whole = _distances(_gap(tmp_path / "whole", raw, tmp_path / "crop", extra=("--names", "raw,crop")))
    assert whole["rays_lost_per_ring"]["raw vs crop"] > 0.5  # every ray outside the crop counts as lost
    rep = _gap(tmp_path / "win", raw, tmp_path / "crop",
               extra=("--names", "raw,crop", "--azimuth=-40:40", "--elevation=-14:90"))
    d = {k: v["raw vs crop"] for k, v in _distances(rep).items()}
    assert d["rays_lost_per_ring"] < 0.01 and d["points_per_range"] < 0.01 and d["intensity"] < 0.01, d
    assert rep["window"] == {"azimuth_deg": [-40.0, 40.0], "elevation_deg": [-14.0, 90.0]}
    assert {r["rays_per_scan"] for r in rep["datasets"]} == {int(cells.sum())}
    lost = rep["metrics"]["rays_lost_per_ring"]["curves"]["raw"]
    floor = ~cells.any(1)  # the rings under the floor hold no ray of the window: no loss rate, not 100 %
    assert floor.sum() > 10 and all((v is None) == f for v, f in zip(lost, floor, strict=True))
