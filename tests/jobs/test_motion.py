"""The flow step of a dataset: every stream's flows and the pair's disparity from the passes on disk."""

from __future__ import annotations

import numpy as np
import pytest

from generator.dataset import Dataset
from generator.formats.kitti_flow import read_disparity_png, read_flow_png
from generator.jobs.motion import write_motion
from kits import motion_kit as mk


@pytest.fixture(scope="module")
def dataset(tmp_path_factory, test_spec, test_scene):
    root = tmp_path_factory.mktemp("motion") / "ds"
    drive = mk.write_dataset(root, test_spec, test_scene, 3, stereo_sweeps=(0, 10, 20))
    record = write_motion(Dataset(root), drive.world, range(3), "00")
    return root, record


def test_every_stream_gets_forward_and_backward_flow(dataset):
    root, record = dataset
    ds = Dataset(root)
    assert record["images"]["images"] == 3 and record["image_2"]["images"] == 3 and record["disparity"]["pairs"] == 3
    first, mid, last = (ds.image_flow(f"{k:06d}_day_clear") for k in range(3))
    assert first.backward is None and first.to == {"forward": "000001"}
    assert mid.to == {"forward": "000002", "backward": "000000"}
    assert last.forward is None and last.backward is not None
    f = ds.stereo_flow(10, 3)
    assert f.to == {"forward": "image_3/000020", "backward": "image_3/000000"}
    assert f.valid("forward").any() and f.valid("forward", visible=True).sum() <= f.valid("forward").sum()


def test_kitti_pngs_hold_the_float_flow(dataset):
    root, _ = dataset
    f = Dataset(root).image_flow("000001_day_clear")
    for folder, bit in (("flow_occ", 1), ("flow_noc", 2)):
        uv, ok = read_flow_png(root / "flow" / folder / "000001.png")
        expected = ((f.forward_flags & bit) > 0) & np.all(np.abs(f.forward) < 511.99, axis=-1)
        np.testing.assert_array_equal(ok, expected)
        assert np.abs(uv - f.forward)[ok].max() <= 1 / 128 + 1e-6
    d = Dataset(root).disparity(10)
    disp, ok = read_disparity_png(root / "lidar/sequences/00/disp_noc_0/000010.png")
    np.testing.assert_array_equal(ok, d.valid(visible=True) & (d.d * 256 <= 65535.5))
    assert np.abs(disp - d.d)[ok].max() <= 1 / 512 + 1e-6
    assert ok.sum() > 0.3 * ok.size


def test_a_stream_of_one_image_gets_no_flow(tmp_path, test_spec, test_scene):
    drive = mk.write_dataset(tmp_path, test_spec, test_scene, 1)
    assert write_motion(Dataset(tmp_path), drive.world, [0], "00") == {}
    assert not (tmp_path / "flow").exists()
