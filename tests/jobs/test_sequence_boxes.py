"""The box records the exports use: from the box file, or rebuilt from the spec without one -- the same."""

from __future__ import annotations

import numpy as np
import pytest

from generator.errors import UserError
from generator.jobs.sequence_boxes import dataset_spec, sequence_boxes


def test_rebuilt_records_equal_the_box_files(traffic_detection_dataset, tmp_path):
    root, spec_path = traffic_detection_dataset
    bare = tmp_path / "bare"
    bare.mkdir()
    (bare / "lidar").symlink_to(root / "lidar")         # the scans without their box file
    stored = sequence_boxes(root, "00", sweeps=[0, 5, 10])
    rebuilt = sequence_boxes(bare, "00", dataset_spec(bare, str(spec_path)), sweeps=[0, 5, 10])
    assert stored.source == "box file" and rebuilt.source == "rebuilt from the spec"
    for j in (0, 5, 10):
        a, b = stored.records[j], rebuilt.records[j]
        assert [r.track_id for r in a] == [r.track_id for r in b] and a
        for r, s in zip(a, b, strict=True):
            assert np.allclose(r.center, s.center) and r.num_lidar_pts == s.num_lidar_pts
            assert r.attribute == s.attribute and r.t == pytest.approx(s.t)


def test_without_box_file_or_spec_one_line_asks_for_the_spec(traffic_detection_dataset, tmp_path):
    root, _ = traffic_detection_dataset
    bare = tmp_path / "bare"
    bare.mkdir()
    (bare / "lidar").symlink_to(root / "lidar")
    with pytest.raises(UserError, match="--spec"):
        sequence_boxes(bare, "00")
    with pytest.raises(UserError, match="manifest.json: missing"):
        dataset_spec(bare)
