"""``urbangen process DIR OUT --domain-gap seed002``: the processed twin holds the same scenes and boxes with
every point count recounted, on a named stream of its own (same input, same bytes)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from generator import cli
from generator.formats import semantickitti as sk
from generator.formats.box_file import read_box_file
from generator.formats.point_sidecars import SIDECARS, read_sidecar
from generator.imaging.paths import image_relpath
from generator.rng import stream
from generator.scan_effects.domain_gap import PRESETS, apply_domain_gap


@pytest.fixture(scope="module")
def twin(traffic_detection_dataset, tmp_path_factory):
    root, _ = traffic_detection_dataset
    out = tmp_path_factory.mktemp("twin") / "twin"
    assert cli.main(["process", str(root), str(out), "--domain-gap", "seed002"]) == 0
    return root, out


def _seq(root):
    return sk.Sequence(root / "lidar", "00")


def test_every_scan_is_the_seed002_processing_of_its_source_on_the_twins_stream(twin):
    root, out = twin
    src, dst = _seq(root), _seq(out)
    seed = json.loads((src.dir / "lidar_meta.json").read_text())["scene"]["seed"]
    assert dst.frames == src.frames
    for j in src.frames:
        pts, sem, inst = src.read_labelled(j)
        keep, xyz, rem, info = apply_domain_gap(pts[:, :3], pts[:, 3], PRESETS["seed002"],
                                                stream(seed, "process", "domain_gap", "00", j))
        got, gsem, ginst = dst.read_labelled(j)
        assert len(got) == len(pts) - round(0.1 * len(pts)) == len(keep)
        assert np.array_equal(got[:, :3], xyz) and np.all(np.abs(got[:, :3] - pts[keep, :3]) <= 0.05 + 1e-5)
        assert np.all(got[:, 3] == np.float32(1 / 255))
        assert np.array_equal(gsem, sem[keep]) and np.array_equal(ginst, inst[keep])
        for folder in SIDECARS:
            a = read_sidecar(src.dir, folder, j, len(pts))
            if a is not None:
                assert np.array_equal(read_sidecar(dst.dir, folder, j, len(got)), a[keep]), folder


def test_box_records_keep_their_boxes_and_count_the_twins_points(twin):
    root, out = twin
    a, b = read_box_file(root / "boxes" / "00.npz"), read_box_file(out / "boxes" / "00.npz")
    dst = _seq(out)
    fewer = 0
    for j in sorted(a.sweeps):
        _, inst = sk.read_labels(dst.label_path(j))
        src = {r.track_id: r for r in a.records(j)}
        for r in b.records(j):
            n = sum(int((inst == i).sum()) for i in r.instance_ids)
            assert r.num_lidar_pts == n >= 1
            s = src[r.track_id]
            assert np.array_equal(r.center, s.center) and r.yaw == s.yaw and r.attribute == s.attribute
            fewer += r.num_lidar_pts < s.num_lidar_pts
        gone = set(src) - {r.track_id for r in b.records(j)}
        assert all(src[t].num_lidar_pts <= 10 for t in gone)           # only boxes of a few points can lose all
    assert fewer > 0


def test_openlabel_counts_follow_and_the_twin_validates(twin):
    root, out = twin
    doc = json.loads((out / "openlabel" / "00.json").read_text())["openlabel"]
    dst = _seq(out)
    bf = read_box_file(out / "boxes" / "00.npz")
    tracks = {int(t): [int(i) for i in ids if i] for t, ids in zip(bf.arrays["track_id"],
                                                                   bf.arrays["track_instance_ids"], strict=True)}
    for key, frame in doc["frames"].items():
        _, inst = sk.read_labels(dst.label_path(int(key)))
        for uid, o in frame["objects"].items():
            n = next(v["val"] for v in o["object_data"]["num"] if v["name"] == "lidar_points")
            assert n == sum(int((inst == i).sum()) for i in tracks.get(int(uid), [int(uid)]))
    assert cli.main(["validate", str(out)]) == 0


def test_the_same_source_gives_the_same_twin_byte_for_byte(twin, tmp_path):
    root, out = twin
    again = tmp_path / "again"
    assert cli.main(["process", str(root), str(again), "--domain-gap", "seed002"]) == 0
    for rel in ("velodyne/000003.bin", "labels/000003.label", "lidar_meta.json"):
        assert (out / "lidar/sequences/00" / rel).read_bytes() == (again / "lidar/sequences/00" / rel).read_bytes()


def test_images_and_the_stereo_stream_come_along_unchanged(frozen_detection_dataset, tmp_path):
    out = tmp_path / "twin"
    assert cli.main(["process", str(frozen_detection_dataset), str(out), "--domain-gap", "seed002",
                     "--dropout", "0.2"]) == 0
    for rel in (image_relpath("000001_day_clear"), "lidar/sequences/00/image_2/000010.png",
                "lidar/sequences/00/passes_3/000020.exr", "lidar/sequences/00/times.txt"):
        assert (out / rel).read_bytes() == (frozen_detection_dataset / rel).read_bytes()
    meta = json.loads((out / "lidar/sequences/00/lidar_meta.json").read_text())
    assert meta["twin_of"]["domain_gap"]["dropout"] == 0.2


def test_bad_input_is_one_line_and_writes_nothing(traffic_detection_dataset, twin, tmp_path, capsys):
    root, out = twin
    assert cli.main(["process", str(root), str(root), "--domain-gap", "seed002"]) == 2
    assert cli.main(["process", str(root), str(out), "--domain-gap", "seed002"]) == 2       # a twin is there
    assert cli.main(["process", str(tmp_path), str(tmp_path / "x"), "--domain-gap", "seed002"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 3 and "exists" in err[1] and not (tmp_path / "x").exists()
