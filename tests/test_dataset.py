"""generator.dataset: one call gives a training loop images, labels, scans, poses and boxes (no Blender)."""

from __future__ import annotations

import numpy as np
import pytest

from generator.dataset import Dataset
from generator.errors import UserError
from generator.formats import semantickitti as sk
from generator.labels import class_table
from kits.fusion_kit import write_raycast_images


@pytest.fixture(scope="module")
def dataset(tmp_path_factory, test_spec, test_scene):
    from generator.jobs.boxes import write_sequence_openlabel
    from generator.jobs.lidar_sequence import SequenceOptions, write_sequence

    root = tmp_path_factory.mktemp("reader")
    write_raycast_images(root, test_scene, test_spec, 2)
    write_sequence(test_scene, test_spec, root / "lidar", SequenceOptions(frames=2, threads=2, bev=False),
                   progress=False)
    write_sequence_openlabel(test_spec, root, scene=test_scene)
    return root


def test_frame_gives_images_scan_and_boxes_in_one_call(dataset):
    ds = Dataset(dataset)
    f = ds.frame(1)
    assert list(f.images) == ["000001_day_clear"]
    img = f.images["000001_day_clear"]
    h, w = img.class_id.shape
    assert img.rgb.shape == (h, w, 3) and img.depth.shape == (h, w) and img.instance.shape == (h, w)
    assert img.meta["frame"] == 1
    rec = sk.Sequence(dataset / "lidar", 0).read(1)
    assert np.array_equal(f.scan.xyz, rec.points[:, :3]) and np.array_equal(f.scan.semantic, rec.semantic)
    assert f.scan.native is not None and len(f.scan.native) == len(f.scan.xyz)
    assert np.array_equal(class_table().to_semantickitti[f.scan.native], f.scan.semantic)
    assert f.scan.pose.shape == (4, 4) and f.scan.time > 0
    assert f.boxes and all(b.cls in ("car", "truck", "person") and b.points > 0 for b in f.boxes)
    assert {b.uid for b in f.boxes} <= {int(i) for i in np.unique(f.scan.instance) if i}


def test_image_labels_in_every_label_set(dataset):
    img = Dataset(dataset).image("000000_day_clear")
    table = class_table()
    assert np.array_equal(img.labels("cityscapes"), table.to_cityscapes[img.class_id])
    assert img.labels("unified11").max() <= 11 and img.labels("semantickitti").max() <= 19
    with pytest.raises(UserError, match="label set"):
        img.labels("coco")


def test_iterating_visits_every_frame(dataset):
    assert [f.index for f in Dataset(dataset)] == [0, 1]


def test_missing_dataset_is_a_user_error(tmp_path):
    with pytest.raises(UserError, match="no such dataset"):
        Dataset(tmp_path / "nope")


def test_an_image_frame_pairs_with_the_sweep_it_was_exposed_with(tmp_path, test_spec, test_scene):
    """A 10 Hz stream: image 1 is exposed with sweep j (> 1); the reader and fusion pair them, not scan 1."""
    from generator.fusion.dataset import FusionDataset
    from generator.jobs.lidar_sequence import SequenceOptions, write_sequence
    from generator.world.rig import Rig

    rig = Rig.from_spec(test_spec, test_scene)
    j = Rig.sweep_of(rig.frame(1))
    assert j > 1
    write_raycast_images(tmp_path, test_scene, test_spec, 2)
    write_sequence(test_scene, test_spec, tmp_path / "lidar",
                   SequenceOptions(frames=j + 1, threads=2, bev=False, image_frames=((0, 0), (1, j))), progress=False)
    ds = Dataset(tmp_path)
    f = ds.frame(1)
    assert f.sweep == j and f.scan.index == j
    assert np.array_equal(f.scan.xyz, sk.Sequence(tmp_path / "lidar", 0).read(j).points[:, :3])
    assert [g.index for g in ds] == [0, 1]
    fusion = FusionDataset(tmp_path)
    assert fusion.frames == [0, 1] and fusion.scan_of[1] == j
    assert np.isclose(fusion.read(1).t_sweep, Rig.sweep_time(j))
