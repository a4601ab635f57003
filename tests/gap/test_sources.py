"""``gap`` sources: a nuScenes root (our own export, with a lidarseg made from its labels) read as scans."""

from __future__ import annotations

import numpy as np
import pytest

from generator.errors import UserError
from generator.formats import semantickitti as sk
from generator.gap.measure import measure
from generator.gap.report import fold_rings, summarize
from generator.gap.sources import open_source
from generator.labels.sets import label_sets
from generator.lidar.sensors import load_preset
from kits.nuscenes_lidarseg import FOLDED, with_lidarseg


@pytest.fixture(scope="module")
def nus(nuscenes_traffic, traffic_detection_dataset, tmp_path_factory):
    root, _ = traffic_detection_dataset
    return with_lidarseg(nuscenes_traffic, root, tmp_path_factory.mktemp("gapnus") / "nus")


def test_the_export_reads_back_as_the_key_frames_of_the_dataset(nus, traffic_detection_dataset):
    root, _ = traffic_detection_dataset
    src = open_source(nus, "REAL")
    assert src.layout == "nuscenes" and src.has_labels and src.has_boxes and not src.has_instances
    assert src.default_sensor() == "hdl64e"  # 64 rings: urbangen's own HDL-64E export
    seq = sk.Sequence(root / "lidar", "00")
    scans = list(src.scans())
    assert len(scans) == len(range(0, len(seq.frames), 5))
    learn = label_sets()["semantickitti"]
    for k, scan in enumerate(scans):
        pts, sem, _ = seq.read_labelled(5 * k)
        # the same points in the same order: ranges equal up to the de-skew (the ego's travel in one sweep)
        r_ours, r_nus = np.linalg.norm(pts[:, :3], axis=1), np.linalg.norm(scan.xyz, axis=1)
        assert np.abs(r_ours - r_nus).max() < 1.5
        # remission quantised to 1/255 (float32 0-255 in the file: exact to float precision)
        assert np.abs(scan.remission - pts[:, 3]).max() < 1e-5
        # classes back as they were, except those nuScenes folds into one of its own
        want = learn.from_raw[sem]
        folded = np.isin(want, [learn.names.index(n) for n in FOLDED])
        assert np.array_equal(scan.learning[~folded], want[~folded])
        assert scan.ring.min() >= 0 and scan.ring.max() < 64


def test_gap_of_a_dataset_and_its_nuscenes_export_is_near_0(nus, traffic_detection_dataset):
    """Same key frames: class mix differs only by the folded classes, intensity by quantisation, range by de-skew."""
    root, _ = traffic_detection_dataset
    ours, theirs = open_source(root, "SYNTH", every=5), open_source(nus, "REAL")
    sensor = load_preset("hdl64e")
    profs = {"ours": measure("ours", ours, sensor, None)[0], "nus": measure("nus", theirs, sensor, None)[0]}
    d = {k: m["distance"]["values"]["ours vs nus"] for k, m in summarize(profs, [("ours", "nus")], None).items()
         if "distance" in m}
    learn = label_sets()["semantickitti"]
    seq = sk.Sequence(root / "lidar", "00")
    lab = np.concatenate([learn.from_raw[seq.read_labelled(j)[1]] for j in range(0, len(seq.frames), 5)])
    lab = lab[lab > 0]
    moved = np.isin(lab, [learn.names.index(n) for n in FOLDED]).mean()
    assert d["class_mix"] == pytest.approx(moved, abs=1e-9)
    assert d["intensity"] < 1e-5 and d["points_per_range"] < 0.01
    assert profs["ours"].points == profs["nus"].points


def test_a_64_ring_profile_folds_to_32_rings_two_at_a_time(nus, traffic_detection_dataset):
    prof, _ = measure("nus", open_source(nus, "REAL"), load_preset("hdl64e"), None)
    half = fold_rings(prof, 32)
    assert half.rings == 32 and half.ring_points.sum() == prof.ring_points.sum()
    assert np.array_equal(half.ring_points, prof.ring_points.reshape(32, 2).sum(1))
    assert np.array_equal(half.residual, prof.residual.reshape(32, 2, -1).sum(1))
    # the same key frames with rings fitted by a 32-ring table: curves on one axis of 32 rings
    h32 = measure("sk", open_source(traffic_detection_dataset[0], "SYNTH", every=5), load_preset("hdl32e_20hz"),
                  None)[0]
    rep = summarize({"a": prof, "b": h32}, [("a", "b")], None)
    assert len(rep["rays_lost_per_ring"]["curves"]["a"]) == 32 == len(rep["rays_lost_per_ring"]["curves"]["b"])
    assert rep["rays_lost_per_ring"]["rings_folded_from"] == {"a": 64, "b": 32}
    assert rep["rays_lost_per_ring"]["distance"]["values"]["a vs b"] is not None
    assert rep["intensity"]["distance"]["values"]["a vs b"] < 1e-5  # ring-free metrics as before
    # a table with fewer rings than the file records is refused, not misread
    with pytest.raises(UserError, match="hdl32e_20hz has 32 rings"):
        measure("nus", open_source(nus, "REAL"), load_preset("hdl32e_20hz"), None)


def test_bad_nuscenes_roots_name_file_and_field(nus, tmp_path):
    import shutil

    half = tmp_path / "half"
    (half / "samples" / "LIDAR_TOP").mkdir(parents=True)
    with pytest.raises(UserError, match="no nuScenes version folder"):
        open_source(half, "REAL")
    broken = tmp_path / "broken"
    shutil.copytree(nus, broken)
    version = next(broken.glob("v1.0-*"))
    (version / "scene.json").unlink()
    with pytest.raises(UserError, match=r"scene\.json: missing"):
        open_source(broken, "REAL")
    shutil.rmtree(broken)
    shutil.copytree(nus, broken)
    label = sorted((broken / "lidarseg").rglob("*_lidarseg.bin"))[0]
    label.write_bytes(label.read_bytes()[:-3])
    with pytest.raises(UserError, match=r"_lidarseg\.bin: lidarseg: \d+ labels for the \d+ points"):
        list(open_source(broken, "REAL").scans())


def test_firings_without_a_return_written_at_the_sensor_are_dropped_as_the_devkit_drops_them(nus, tmp_path):
    """A real nuScenes sweep holds every firing; a beam without a return (or on the ego's roof) is a point by the
    sensor. Such points (within 1 m in x and y, the devkit's remove_close) are no returns: the scan reads as before."""
    import json
    import shutil

    root = tmp_path / "nus"
    shutil.copytree(nus, root)
    before = [s.xyz for s in open_source(nus, "REAL").scans()]
    sweep = sorted((root / "samples" / "LIDAR_TOP").glob("*.pcd.bin"))[0]
    pts = np.fromfile(sweep, np.float32).reshape(-1, 5)
    idle = np.zeros((50, 5), np.float32)
    idle[:, :3] = np.random.default_rng(0).uniform(-0.9, 0.9, (50, 3))
    idle[:, 4] = np.arange(50) % 32
    np.concatenate([pts, idle]).tofile(sweep)
    version = next(root.glob("v1.0-*"))
    token = next(r["token"] for r in json.loads((version / "sample_data.json").read_text())
                 if r["filename"].endswith(sweep.name))
    rel = next(r["filename"] for r in json.loads((version / "lidarseg.json").read_text())
               if r["sample_data_token"] == token)
    lab = root / rel  # one label per point, as the lidarseg of a real sweep has
    np.concatenate([np.fromfile(lab, np.uint8), np.zeros(50, np.uint8)]).tofile(lab)
    after = [s.xyz for s in open_source(root, "REAL").scans()]
    assert len(after) == len(before) and all(np.array_equal(a, b) for a, b in zip(after, before, strict=True))
