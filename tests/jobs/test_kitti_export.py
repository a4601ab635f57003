"""``export kitti-object`` of a cast test town with a ray-cast stereo stream: the KITTI layout, and what a
KITTI tool computes from it (calib, labels, velodyne) agrees with the boxes."""

from __future__ import annotations

import numpy as np
import pytest

from generator import cli
from generator.formats.box_file import read_box_file
from generator.formats.kitti_calib import read_calib
from generator.formats.kitti_object import read_labels
from generator.labels.detection import KITTI_TYPES
from kits.stereo_kit import write_raycast_stereo

SWEEPS = 21
PAIRS = (0, 10, 20)


@pytest.fixture(scope="module")
def export(tmp_path_factory, test_spec, test_scene):
    from generator.jobs.box_labels import write_sequence_boxes
    from generator.jobs.lidar_sequence import SequenceOptions, write_sequence

    root = tmp_path_factory.mktemp("kittids")
    write_sequence(test_scene, test_spec, root / "lidar", SequenceOptions(frames=SWEEPS, threads=2, bev=False),
                   progress=False)
    write_raycast_stereo(root, test_scene, test_spec, PAIRS)
    write_sequence_boxes(test_spec, root, scene=test_scene)
    out = root.parent / (root.name + "_kitti")
    assert cli.main(["export", "kitti-object", str(root), str(out)]) == 0
    return root, out


def test_the_kitti_layout(export):
    _, out = export
    ids = [f"{k:06d}" for k in range(len(PAIRS))]
    for sub, ext in (("velodyne", "bin"), ("image_2", "png"), ("image_3", "png"), ("label_2", "txt"), ("calib", "txt")):
        assert sorted(p.stem for p in (out / "training" / sub).glob(f"*.{ext}")) == ids, sub
    train = (out / "ImageSets" / "train.txt").read_text().split()
    val = (out / "ImageSets" / "val.txt").read_text().split()
    assert sorted(train + val) == ids and not set(train) & set(val) and train and val
    assert (out / "ImageSets" / "test.txt").read_text() == ""
    assert [ln.split()[2] for ln in (out / "mapping.txt").read_text().splitlines()] == [f"{j:06d}" for j in PAIRS]
    calib = read_calib(out / "training" / "calib" / "000001.txt")
    assert list(calib) == ["P0", "P1", "P2", "P3", "R0_rect", "Tr_velo_to_cam", "Tr_imu_to_velo"]


def test_labels_agree_with_the_points_as_a_kitti_tool_reads_them(export):
    """Velodyne points through Tr_velo_to_cam and R0_rect land in the label box of their thing."""
    root, out = export
    bf = read_box_file(root / "boxes" / "00.npz")
    checked = 0
    for k, j in enumerate(PAIRS):
        sid = f"{k:06d}"
        labels = read_labels(out / "training" / "label_2" / f"{sid}.txt")
        assert {o.type for o in labels} <= set(KITTI_TYPES) and labels
        calib = read_calib(out / "training" / "calib" / f"{sid}.txt")
        pts = np.fromfile(out / "training" / "velodyne" / f"{sid}.bin", np.float32).reshape(-1, 4)[:, :3]
        rect = (pts @ calib["Tr_velo_to_cam"][:, :3].T + calib["Tr_velo_to_cam"][:, 3]) @ calib["R0_rect"].T
        inst = (np.fromfile(root / "lidar" / "sequences" / "00" / "labels" / f"{j:06d}.label", np.uint32) >> 16)
        kept = [rec for rec, vis in bf.image(f"image_2/{j:06d}").boxes if rec.num_lidar_pts >= 1]
        things = [o for o in labels if o.type != "DontCare"]
        assert len(things) == len(kept)
        for o, rec in zip(things, kept, strict=True):
            h, w, length = o.dimensions
            x, y, z = o.location
            c, s = np.cos(o.rotation_y), np.sin(o.rotation_y)
            d = rect - [x, y, z]
            along, across = d[:, 0] * c - d[:, 2] * s, d[:, 0] * s + d[:, 2] * c
            inside = (np.abs(along) <= length / 2 + 0.15) & (np.abs(across) <= w / 2 + 0.15) & \
                     (d[:, 1] <= 0.15) & (d[:, 1] >= -h - 0.15)
            mine = np.isin(inst, rec.instance_ids) & (rect[:, 2] > 0)
            assert inside[mine].mean() > 0.98, (sid, o.type, rec.name)
            # the 2D box lies within the projection of the 3D box (it is the footprint's extent)
            P2 = calib["P2"]
            corners = np.array([[sx * length / 2, -hy, sz * w / 2]
                                for sx in (-1, 1) for sz in (-1, 1) for hy in (0, h)])
            R = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
            cam = corners @ R.T + [x, y, z]
            if (cam[:, 2] > 0.5).all():
                uv = (cam @ P2[:, :3].T + P2[:, 3])
                uv = uv[:, :2] / uv[:, 2:]
                assert o.bbox[0] >= uv[:, 0].min() - 1.5 and o.bbox[2] <= uv[:, 0].max() + 1.5
                assert o.bbox[1] >= uv[:, 1].min() - 1.5 and o.bbox[3] <= uv[:, 1].max() + 1.5
            checked += 1
    assert checked >= 5


def test_an_existing_export_is_not_overwritten(export, capsys):
    root, out = export
    assert cli.main(["export", "kitti-object", str(root), str(out)]) == 2
    assert "already holds a KITTI export" in capsys.readouterr().err
