"""Seed 002 Table 1 in ``urbangen stats``: one annotation per box per sweep, by seed 002's classes."""

from __future__ import annotations

import collections

from generator.formats.box_file import read_box_file
from generator.labels.nuscenes import nuscenes_labels
from generator.stats import box_counts, section_modules


def test_table1_counts_every_box_of_every_sweep_by_its_detection_class(traffic_detection_dataset):
    root, _ = traffic_detection_dataset
    bf = read_box_file(root / "boxes" / "00.npz")
    labels = nuscenes_labels()
    want = collections.Counter(labels.detection_class(r.cls, r.kind) for j in bf.sweeps for r in bf.records(j))
    data = box_counts.load(root)
    assert data.sweeps == 11 and data.sources == ["boxes/00.npz"]
    assert {c: n for c, n in data.counts.items() if n} == {c: n for c, n in want.items()}
    t = box_counts.section(data).tables[0]
    rows = {r[0]: r for r in t.rows}
    assert rows["total"][1] == sum(want.values()) and rows["car"][3] == 48_878 and rows["total"][3] == 156_324
    assert [r[0] for r in t.rows] == ["car", "truck", "bus", "pedestrian", "motorcycle", "bicycle", "other", "total"]


def test_without_box_files_the_openlabel_cuboids_count_and_without_either_no_section(traffic_detection_dataset,
                                                                                     tmp_path):
    root, _ = traffic_detection_dataset
    only_ol = tmp_path / "ol"
    (only_ol / "lidar").mkdir(parents=True)
    (only_ol / "lidar" / "sequences").symlink_to(root / "lidar" / "sequences")
    (only_ol / "openlabel").symlink_to(root / "openlabel")
    assert box_counts.load(only_ol).counts == box_counts.load(root).counts
    assert box_counts.load(tmp_path / "nothing") is None
    assert box_counts in section_modules()
