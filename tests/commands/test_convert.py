"""Label conversion native -> SemanticKITTI raw -> unified 11: round trips, the convert command, errors."""

from __future__ import annotations

import filecmp
import json

import numpy as np
import pytest
import yaml

import generator.cli as cli
from generator.formats import semantickitti as sk
from generator.labels import class_table
from generator.labels.sets import native_to_semantickitti, semantickitti_to_unified, unified_to_semantickitti


@pytest.fixture(autouse=True)
def only_ours(monkeypatch):
    monkeypatch.setattr(cli, "COMMANDS", ["convert"])


def test_native_to_raw_to_unified_is_the_composition_for_every_class():
    table = class_table()
    native = np.arange(len(table))
    raw = native_to_semantickitti(native)
    uni = semantickitti_to_unified(raw)
    assert np.array_equal(uni, table.to_unified)
    expected = {"car": "vehicle", "truck": "vehicle", "person": "person", "road": "road", "road_marking": "road",
                "crosswalk": "road", "curb": "sidewalk", "sidewalk": "sidewalk", "parking": "other-ground",
                "terrain": "terrain", "building": "building", "fence": "fence", "vegetation": "vegetation",
                "tree_trunk": "vegetation", "tree_crown": "vegetation", "pole": "pole", "traffic_light": "traffic-sign",
                "traffic_sign": "traffic-sign", "unlabeled": "unlabeled", "sky": "unlabeled",
                "bicycle": "vehicle", "motorcycle": "vehicle", "bus": "vehicle", "on_rails": "vehicle",
                "other_vehicle": "vehicle", "bicyclist": "person", "motorcyclist": "person", "wall": "fence",
                "other_ground": "other-ground", "street_object": "unlabeled", "rail_track": "other-ground",
                "shelter": "unlabeled", "ridden_bicycle": "person", "ridden_motorcycle": "person"}
    assert {n: table.unified_names[int(u)] for n, u in zip(table.names, uni, strict=False)} == expected


def test_raw_unified_canonical_raw_round_trip_is_identity_on_unified():
    table = class_table()
    raw = np.array(sorted(table.sk_labels), np.uint16)  # every raw id of the reference config
    uni = semantickitti_to_unified(raw)
    assert np.array_equal(semantickitti_to_unified(unified_to_semantickitti(uni)), uni)
    every = np.arange(12)
    assert np.array_equal(semantickitti_to_unified(unified_to_semantickitti(every)), every)


def write_native_dataset(root, seq="00", frames=3, seed=0):
    """A dataset as urbangen writes it: one point per native class per scan plus random ones."""
    g = np.random.default_rng(seed)
    table = class_table()
    natives = []
    d = root / "sequences" / seq
    for k in range(frames):
        native = np.concatenate([np.arange(len(table)), g.integers(0, len(table), 500)])
        inst = g.integers(0, 1000, len(native)).astype(np.uint16)
        sk.write_scan(d / "velodyne" / f"{k:06d}.bin", g.normal(0, 10, (len(native), 3)), g.uniform(0, 1, len(native)))
        sk.write_labels(d / "labels" / f"{k:06d}.label", table.to_semantickitti[native], inst)
        natives.append((native, inst))
    poses = np.repeat(np.eye(4)[None], frames, 0)
    poses[:, 0, 3] = np.arange(frames)
    sk.write_poses(d / "poses.txt", poses)
    sk.write_times(d / "times.txt", np.arange(frames) * 0.1)
    (d / "calib.txt").write_text("P0: " + " ".join(["0"] * 12) + "\nTr: 1 0 0 0 0 1 0 0 0 0 1 0\n")
    return natives


def test_convert_command_rewrites_labels_keeps_instances_and_copies_the_rest(tmp_path, capsys):
    table = class_table()
    src, dst = tmp_path / "src", tmp_path / "dst"
    natives = write_native_dataset(src, "00")
    write_native_dataset(src, "03", frames=2, seed=1)
    assert cli.main(["convert", str(src), str(dst), "--labels", "unified11"]) == 0
    assert "converted 5 scans of sequences 00, 03" in capsys.readouterr().out
    for k, (native, inst) in enumerate(natives):
        uni, inst2 = sk.read_labels(dst / "sequences" / "00" / "labels" / f"{k:06d}.label")
        assert np.array_equal(uni, table.to_unified[native]) and np.array_equal(inst2, inst)
        assert filecmp.cmp(src / "sequences" / "00" / "velodyne" / f"{k:06d}.bin",
                           dst / "sequences" / "00" / "velodyne" / f"{k:06d}.bin", shallow=False)
    for f in ("poses.txt", "calib.txt", "times.txt"):
        assert filecmp.cmp(src / "sequences" / "00" / f, dst / "sequences" / "00" / f, shallow=False)
    cfg = yaml.safe_load((dst / "unified11.yaml").read_text())
    assert cfg["labels"] == {i: n for i, n in table.unified_names.items()}
    assert cfg["color_map"][1] == table.sk_colors_bgr[10] and cfg["color_map"][3] == table.sk_colors_bgr[40]
    assert cfg["learning_map"] == {i: i for i in range(12)} and cfg["learning_map_inv"] == {i: i for i in range(12)}
    assert cfg["learning_ignore"][0] is True and not any(cfg["learning_ignore"][i] for i in range(1, 12))
    assert abs(sum(cfg["content"].values()) - 1) < 1e-9 and cfg["split"]["valid"] == [0, 3]
    summary = json.loads((dst / "conversion.json").read_text())
    assert summary["scans"] == 5 and summary["labels"] == "unified11"
    assert not [p for p in dst.iterdir() if p.name.startswith(".tmp-")]
    # the converted dataset reads like any SemanticKITTI dataset
    seq = sk.Sequence(dst, 0)
    assert len(seq) == 3 and seq.lidar_poses() is not None


def test_convert_selected_sequences_only(tmp_path):
    write_native_dataset(tmp_path / "src", "00")
    write_native_dataset(tmp_path / "src", "01")
    assert cli.main(["convert", str(tmp_path / "src"), str(tmp_path / "dst"), "--labels", "unified11",
                     "--sequences", "01"]) == 0
    assert sk.list_sequences(tmp_path / "dst") == ["01"]


@pytest.mark.parametrize("case, message", [
    ("unknown_raw", "are not SemanticKITTI labels (already converted?)"),
    ("missing_seq", "sequence not found"),
    ("same_dir", "output must differ from the input"),
    ("count_mismatch", "labels but"),
    ("bad_labels_option", "invalid choice"),
    ("empty_seq", "no scans; nothing to convert"),
])
def test_bad_input_one_line_exit_2_nothing_written(tmp_path, capsys, case, message):
    src, dst = tmp_path / "src", tmp_path / "dst"
    write_native_dataset(src, "00")
    args = ["convert", str(src), str(dst), "--labels", "unified11"]
    if case == "unknown_raw":  # the last scan holds an id SemanticKITTI does not have: nothing may be written
        sk.write_labels(src / "sequences" / "00" / "labels" / "000002.label", np.full(507, 5, np.uint16),
                        np.zeros(507, np.uint16))
        sk.write_scan(src / "sequences" / "00" / "velodyne" / "000002.bin", np.zeros((507, 3)), np.zeros(507))
    elif case == "missing_seq":
        args += ["--sequences", "04"]
    elif case == "same_dir":
        args[2] = str(src)
    elif case == "count_mismatch":
        sk.write_scan(src / "sequences" / "00" / "velodyne" / "000001.bin", np.zeros((3, 3)), np.zeros(3))
    elif case == "bad_labels_option":
        args[-1] = "cityscapes"
    elif case == "empty_seq":  # a sequence with its folders and calib but no scan (converted "0 scans" before)
        d = src / "sequences" / "00"
        for f in [*(d / "velodyne").iterdir(), *(d / "labels").iterdir(), d / "poses.txt", d / "times.txt"]:
            f.unlink()
    try:
        rc = cli.main(args)
    except SystemExit as e:  # argparse's own errors
        rc = e.code
    err = capsys.readouterr().err
    assert rc == 2 and message in err and err.count("\n") == 1, err
    assert not dst.exists()


def test_existing_output_sequence_is_not_overwritten(tmp_path, capsys):
    write_native_dataset(tmp_path / "src", "00")
    (tmp_path / "dst" / "sequences" / "00").mkdir(parents=True)
    assert cli.main(["convert", str(tmp_path / "src"), str(tmp_path / "dst"), "--labels", "unified11"]) == 2
    assert "exists; remove it" in capsys.readouterr().err
    assert list((tmp_path / "dst").iterdir()) == [tmp_path / "dst" / "sequences"]
