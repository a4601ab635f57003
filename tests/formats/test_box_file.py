"""The box file round trip (boxes/NN.npz) and its refusal of damaged files."""

from __future__ import annotations

import numpy as np
import pytest

from generator.detection.records import BoxRecord
from generator.detection.visibility import ImageBox
from generator.errors import SpecError
from generator.formats.box_file import ImageEntry, read_box_file, write_box_file


def _rec(sweep, track, t, ids=None, cls="car"):
    T = np.eye(4)
    T[:3, 3] = [t, 0.0, 1.73]
    return BoxRecord(sweep, t, track, ids or (track,), cls, cls, f"{cls}_{track}", np.array([t, 2.0, 0.8]),
                     np.array([4.2, 1.8, 1.5]), 0.3, np.array([1.0, 0.0, 0.0]), np.zeros(3), True, "vehicle.moving",
                     10 * track, T, False)


@pytest.fixture
def written(tmp_path):
    recs = [_rec(0, 5, 0.01), _rec(0, 7, 0.02, (7, 8), "bicyclist"), _rec(1, 5, 0.11)]
    amodal, visible = np.array([1.0, 2.0, 30.0, 20.0]), np.array([5.0, 2.0, 30.0, 20.0])
    vis = ImageBox(5, amodal, visible, 400, 300, 0.1, 0.75, 1, 2, "3")
    K = np.diag([100.0, 100.0, 1.0])
    entry = ImageEntry("image_2/000001", 1, 0.15, np.eye(4), K, 64, 48, [(_rec(1, 5, 0.15), vis)], np.eye(4))
    path = tmp_path / "boxes" / "00.npz"
    write_box_file(path, {0: 0.0, 1: 0.1}, recs, [entry], {"sequence": "00", "T_ego_lidar": np.eye(4).tolist()})
    return path, recs, entry


def test_records_and_images_round_trip(written):
    path, recs, entry = written
    bf = read_box_file(path)
    assert bf.sweeps == {0: 0.0, 1: 0.1} and bf.info["sequence"] == "00"
    got = bf.records(0) + bf.records(1)
    assert [(r.sweep, r.track_id, r.instance_ids, r.cls, r.num_lidar_pts) for r in got] == \
        [(r.sweep, r.track_id, r.instance_ids, r.cls, r.num_lidar_pts) for r in recs]
    for a, b in zip(got, recs, strict=True):
        np.testing.assert_array_equal(a.center, b.center)
        np.testing.assert_array_equal(a.T_world_lidar, b.T_world_lidar)
        assert a.t == b.t and a.yaw == b.yaw and a.attribute == b.attribute
    assert bf.records(9) == []
    e = bf.image("image_2/000001")
    (r, v), = e.boxes
    assert e.sweep == 1 and e.width == 64 and r.track_id == 5 and v.visibility == 0.75 and v.nuscenes_visibility == "3"
    np.testing.assert_array_equal(v.bbox_visible, [5.0, 2.0, 30.0, 20.0])
    assert bf.image("images/000004") is None


def test_same_records_same_bytes(written, tmp_path):
    path, recs, entry = written
    again = tmp_path / "again.npz"
    write_box_file(again, {0: 0.0, 1: 0.1}, recs, [entry], {"sequence": "00", "T_ego_lidar": np.eye(4).tolist()})
    assert again.read_bytes() == path.read_bytes()


def test_a_damaged_file_is_one_line(written, tmp_path):
    path, _, _ = written
    data = path.read_bytes()
    cut = tmp_path / "cut.npz"
    cut.write_bytes(data[: len(data) // 2])
    with pytest.raises(SpecError, match="cut.npz: .*damaged or truncated"):
        read_box_file(cut)
    arrays = dict(np.load(path))
    arrays["center"] = arrays["center"][:1]           # a column of the wrong length
    bad = tmp_path / "bad.npz"
    np.savez(bad, **arrays)
    with pytest.raises(SpecError, match="bad.npz: center: wrong dtype or shape"):
        read_box_file(bad)
    arrays = dict(np.load(path))
    arrays["yaw"][0] = np.nan
    np.savez(bad, **arrays)
    with pytest.raises(SpecError, match="yaw: must be finite"):
        read_box_file(bad)
