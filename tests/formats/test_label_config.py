"""The label config's ``split`` lists every sequence written, under the split asked for or ``valid``.

semantic-kitti-api's ``evaluate_semantics.py`` / ``evaluate_panoptic.py`` evaluate the
sequences the config lists under ``valid`` unless given ``-s``: a generated dataset must be
found with default flags, and a dataset with several sequences must keep all of them.
"""

from __future__ import annotations

import numpy as np
import pytest
import yaml

import generator.cli as cli
from generator.formats import semantickitti as sk
from generator.formats.label_config import merge_split
from generator.jobs.lidar_sequence import write_dataset_label_config


def _sequence(root, name: str, raw=(40, 40, 50)) -> None:
    d = sk.sequence_dir(root, name)
    raw = np.array(raw, np.uint16)
    sk.write_scan(d / "velodyne" / "000000.bin", np.zeros((len(raw), 3)), np.zeros(len(raw)))
    sk.write_labels(d / "labels" / "000000.label", raw, np.zeros(len(raw), np.uint16))


def _split(path) -> dict:
    return yaml.safe_load(path.read_text())["split"]


def test_merge_split_places_each_present_sequence_once():
    before = {"train": [0, 4], "valid": [1], "test": [9]}
    assert merge_split([0, 1, 2, 3], {3: "test"}, before) == {"train": [0], "valid": [1, 2], "test": [3]}
    assert merge_split([0, 1], {0: "valid", 1: "valid"}, before) == {"train": [], "valid": [0, 1], "test": []}
    with pytest.raises(ValueError):
        merge_split([0], {0: "val"})


def test_dataset_config_merges_with_what_is_on_disk(tmp_path):
    _sequence(tmp_path, "00")
    assert write_dataset_label_config(tmp_path)["split"] == {"train": [], "valid": [0], "test": []}
    write_dataset_label_config(tmp_path, "train", ["00"])
    _sequence(tmp_path, "03", raw=(10, 10, 10))  # a second sequence: 00 keeps train, 03 goes to valid
    cfg = write_dataset_label_config(tmp_path)
    assert _split(tmp_path / "semantic-kitti.yaml") == {"train": [0], "valid": [3], "test": []}
    assert cfg["content"][10] == pytest.approx(3 / 6) and cfg["content"][40] == pytest.approx(2 / 6)
    write_dataset_label_config(tmp_path, "test", ["03"])
    assert _split(tmp_path / "semantic-kitti.yaml") == {"train": [0], "valid": [], "test": [3]}


def test_convert_split_option_and_default(tmp_path, monkeypatch):
    monkeypatch.setattr(cli, "COMMANDS", ["convert"])
    src = tmp_path / "src"
    for name in ("00", "01"):
        _sequence(src, name)
    write_dataset_label_config(src, "train", ["00"])  # the source says 00 is train, 01 valid
    assert cli.main(["convert", str(src), str(tmp_path / "a"), "--labels", "unified11"]) == 0
    assert _split(tmp_path / "a" / "unified11.yaml") == {"train": [0], "valid": [1], "test": []}
    assert cli.main(["convert", str(src), str(tmp_path / "b"), "--labels", "unified11", "--sequences", "01",
                     "--split", "test"]) == 0
    assert _split(tmp_path / "b" / "unified11.yaml") == {"train": [], "valid": [], "test": [1]}
    # a second run into the same output adds 00 and keeps 01 where it was
    assert cli.main(["convert", str(src), str(tmp_path / "b"), "--labels", "unified11", "--sequences", "00"]) == 0
    assert _split(tmp_path / "b" / "unified11.yaml") == {"train": [0], "valid": [], "test": [1]}
    assert cli.main(["convert", str(src), str(tmp_path / "c"), "--labels", "unified11", "--split", "val"]) == 2
    assert not (tmp_path / "c").exists()


def test_lidar_command_split_option(root, tmp_path, monkeypatch):
    pytest.importorskip("generator.layout.assemble")
    monkeypatch.setattr(cli, "COMMANDS", ["lidar"])
    spec, out = str(root / "scenes" / "test_town.json"), tmp_path / "ds"
    assert cli.main(["-q", "lidar", spec, "--out", str(out), "--frames", "1", "--no-bev", "--threads", "2"]) == 0
    assert _split(out / "lidar" / "semantic-kitti.yaml") == {"train": [], "valid": [0], "test": []}
    assert cli.main(["-q", "lidar", spec, "--out", str(out), "--frames", "1", "--no-bev", "--threads", "2",
                     "--sequence", "01", "--split", "train"]) == 0
    assert _split(out / "lidar" / "semantic-kitti.yaml") == {"train": [1], "valid": [0], "test": []}
