"""SemanticKITTI files: bit layout, sizes, poses/calib conventions, label config, reader errors, determinism."""

from __future__ import annotations

import filecmp
from pathlib import Path

import numpy as np
import pytest
import yaml

from generator.errors import UserError
from generator.formats import kitti_calib
from generator.formats import semantickitti as sk
from generator.formats.label_config import label_config, merge_split
from generator.formats.ply import read_ply, write_ply
from generator.geometry import box, rect
from generator.jobs.lidar_sequence import SequenceOptions, write_sequence
from generator.labels import class_table
from generator.world import rig
from generator.world.rig import Rig
from kits.scene_kit import scene_of, straight_path
from kits.sensor_kit import with_lidar

HEADING = 0.7  # a diagonal route, so the pose chain is tested with a rotation


def test_label_bits_round_trip(rng):
    sem = rng.choice(np.array(list(class_table().sk_labels), np.uint16), 1000)
    inst = rng.integers(0, 65536, 1000).astype(np.uint16)
    inst[:3] = [0, 1, 65535]
    raw = sk.encode_labels(sem, inst)
    assert raw.dtype == np.uint32
    assert np.array_equal(raw & 0xFFFF, sem) and np.array_equal(raw >> 16, inst)
    s2, i2 = sk.decode_labels(raw)
    assert np.array_equal(s2, sem) and np.array_equal(i2, inst)


def test_scan_and_label_files_round_trip(tmp_path, rng):
    xyz = rng.normal(0, 20, (777, 3)).astype(np.float32)
    rem = rng.uniform(0, 1, 777).astype(np.float32)
    sem = np.full(777, 40, np.uint16)
    inst = rng.integers(0, 300, 777).astype(np.uint16)
    sk.write_scan(tmp_path / "a.bin", xyz, rem)
    sk.write_labels(tmp_path / "a.label", sem, inst)
    assert (tmp_path / "a.bin").stat().st_size == 777 * 16 and (tmp_path / "a.label").stat().st_size == 777 * 4
    pts = sk.read_scan(tmp_path / "a.bin")
    assert pts.dtype == np.float32 and pts.shape == (777, 4)
    assert np.array_equal(pts[:, :3], xyz) and np.array_equal(pts[:, 3], rem)
    s, i = sk.read_labels(tmp_path / "a.label")
    assert np.array_equal(s, sem) and np.array_equal(i, inst)


def test_reader_errors_name_the_file(tmp_path):
    (tmp_path / "bad.bin").write_bytes(b"\0" * 18)
    with pytest.raises(UserError, match=r"bad\.bin: size 18 bytes is not a multiple of the record size \(16 bytes\)"):
        sk.read_scan(tmp_path / "bad.bin")
    with pytest.raises(UserError, match=r"missing\.label: file not found"):
        sk.read_labels(tmp_path / "missing.label")
    (tmp_path / "poses.txt").write_text("1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1\n")
    with pytest.raises(UserError, match=r"poses\.txt: line 2: expected 12 numbers, got 11"):
        sk.read_poses(tmp_path / "poses.txt")
    seq = tmp_path / "ds" / "sequences" / "03"
    sk.write_scan(seq / "velodyne" / "000000.bin", np.zeros((5, 3)), np.zeros(5))
    sk.write_labels(seq / "labels" / "000000.label", np.zeros(4, np.uint16), np.zeros(4, np.uint16))
    with pytest.raises(UserError, match=r"000000\.label: 4 labels but .*000000\.bin has 5 points"):
        list(sk.iter_sequence(tmp_path / "ds", 3))
    with pytest.raises(UserError, match="sequence must be a number"):
        sk.sequence_dir(tmp_path, "../x")


def test_calib_from_the_rig_is_kitti_like(default_spec, tmp_path):
    calib = kitti_calib.kitti_calib(Rig.from_spec(default_spec), 640, 360)
    tr = kitti_calib.homogeneous(calib["Tr"])
    # velodyne x forward -> camera z; y left -> -x; z up -> -y (KITTI's Tr rotation)
    np.testing.assert_allclose(tr[:3, :3], [[0, -1, 0], [0, 0, -1], [1, 0, 0]], atol=1e-12)
    np.testing.assert_allclose(tr[:3, 3], [0.0, -0.08, -0.27], atol=1e-12)  # lidar 8 cm above, 27 cm behind the camera
    k = rig.intrinsics(default_spec.sensors.camera.hfov_deg, 640, 360)
    for key in ("P0", "P2"):  # the left camera (image_2) is the rectified reference
        np.testing.assert_array_equal(calib[key], np.hstack([k, np.zeros((3, 1))]))
    for key in ("P1", "P3"):  # the right one, 0.54 m to its right: -fx * b in the last column, like KITTI
        np.testing.assert_allclose(calib[key], np.hstack([k, [[-k[0, 0] * 0.54], [0.0], [0.0]]]), atol=1e-9)
    kitti_calib.write_calib(tmp_path / "calib.txt", calib)
    back = kitti_calib.read_calib(tmp_path / "calib.txt")
    assert list(back) == ["P0", "P1", "P2", "P3", "Tr"]
    for key in back:
        np.testing.assert_allclose(back[key], calib[key], rtol=1e-12, atol=1e-12)
    # a lidar point projects through P2 @ Tr where the rig camera sees it
    p_velo = np.array([10.0, 1.0, -0.5, 1.0])
    uvw = calib["P2"] @ tr @ p_velo
    cam = rig.invert(rig.camera_extrinsics(default_spec.sensors.camera.xyz_m, default_spec.sensors.camera.rpy_deg)) \
        @ rig.mount(default_spec.sensors.lidar.xyz_m, default_spec.sensors.lidar.rpy_deg) @ p_velo
    np.testing.assert_allclose(uvw[:2] / uvw[2], (k @ cam[:3])[:2] / cam[2])


def test_camera_and_lidar_pose_conventions(rng):
    tr = kitti_calib.homogeneous(np.hstack([[[0, -1, 0], [0, 0, -1], [1, 0, 0]], [[0.01], [-0.08], [-0.27]]]))
    t_world_velo = np.stack([rig.ego_pose(rng.normal(0, 50, 3), rng.uniform(-3, 3)) for _ in range(5)])
    cam = kitti_calib.camera_poses(t_world_velo, tr)
    np.testing.assert_allclose(cam[0], np.eye(4), atol=1e-12)
    velo = kitti_calib.lidar_poses(cam, tr)  # what the SemanticKITTI API computes
    np.testing.assert_allclose(velo, rig.invert(t_world_velo[0]) @ t_world_velo, atol=1e-9)


def test_label_config_matches_the_reference_format():
    ref = class_table().sk_config
    cfg = yaml.safe_load(__import__("generator.formats.label_config", fromlist=["x"]).format_label_config(
        label_config({40: 30, 50: 10, 10: 0}, merge_split([0, 3]))))
    for section in ("labels", "color_map", "learning_map", "learning_map_inv", "learning_ignore"):
        assert cfg[section] == ref[section], section
    assert set(cfg["content"]) == set(ref["labels"])
    assert cfg["content"][40] == 0.75 and cfg["content"][50] == 0.25 and cfg["content"][10] == 0.0
    assert cfg["split"] == {"train": [], "valid": [0, 3], "test": []}  # semantic-kitti-api evaluates valid by default
    with pytest.raises(ValueError):
        label_config({12345: 1}, merge_split([0]))


def test_ply_round_trip(tmp_path, rng):
    xyz = rng.normal(0, 10, (50, 3)).astype(np.float32)
    sem = np.full(50, 10, np.uint16)
    rgb = np.tile(np.array([[0, 0, 142]], np.uint8), (50, 1))
    write_ply(tmp_path / "s.ply", xyz, np.full(50, 0.5, np.float32), sem, np.arange(50, dtype=np.uint16), rgb)
    v = read_ply(tmp_path / "s.ply")
    assert np.array_equal(v["x"], xyz[:, 0]) and np.all(v["semantic"] == 10) and np.all(v["blue"] == 142)
    assert (tmp_path / "s.ply").read_bytes().startswith(b"ply\nformat binary_little_endian 1.0\n")


# -- whole sequences ---------------------------------------------------------------------------
def _static_scene():
    d = np.array([np.cos(HEADING), np.sin(HEADING)])
    n = np.array([-d[1], d[0]])
    c1 = 20 * d + 6 * n  # a box left of the route, 20 m ahead of the start
    c2 = 45 * d - 7 * n
    return scene_of([("ground", rect(-300, -300, 300, 300, 0.0, "road", "asphalt"), 0),
                     ("box_a", box((3.0, 3.0, 5.0), "building", "facade_brick", center=(c1[0], c1[1], 2.5)), 11),
                     ("box_b", box((2.0, 2.0, 3.0), "car", "car_paint", center=(c2[0], c2[1], 1.5)), 12)],
                    paths=[straight_path(0.0, 300.0, heading=HEADING)])


def _no_skew(spec):
    return with_lidar(spec, motion_skew=False, returns="ideal")  # points on their faces to the millimetre


def _box_distance(p, center, size):
    q = np.abs(p - center) - np.asarray(size) / 2
    return np.linalg.norm(np.maximum(q, 0), axis=1) + np.minimum(q.max(1), 0)


def test_written_sequence_sizes_and_static_objects_stay_put(test_spec, tmp_path):
    spec = _no_skew(test_spec)
    scene = _static_scene()
    meta = write_sequence(scene, spec, tmp_path, SequenceOptions(frames=4, sequence="05", threads=2), progress=False)
    seq = sk.Sequence(tmp_path, 5)
    assert len(seq) == 4 and seq.frames == [0, 1, 2, 3]
    np.testing.assert_allclose(seq.times, [0.0, 0.1, 0.2, 0.3])  # a 10 Hz stream, as KITTI's
    # lidar pose of scan 0 in the world, from the route and the mount
    t_world_velo0 = rig.ego_pose(scene.paths[0].points[0], HEADING) @ rig.mount(spec.sensors.lidar.xyz_m,
                                                                                spec.sensors.lidar.rpy_deg)
    boxes = {50: (scene.objects[1].box.center, scene.objects[1].box.size), 10: (scene.objects[2].box.center,
                                                                                scene.objects[2].box.size)}
    seen = {50: 0, 10: 0}
    for rec, n in zip(seq, meta["points_per_scan"], strict=False):
        assert rec.points.shape == (n, 4) and len(rec.semantic) == n
        assert seq.scan_path(rec.index).stat().st_size // 16 == seq.label_path(rec.index).stat().st_size // 4
        assert (rec.points[:, 3] >= 0).all() and (rec.points[:, 3] <= 1).all()  # class_normal, clipped to [0, 1]
        road_rem = rec.points[rec.semantic == 40, 3]
        assert abs(road_rem.mean() - 0.303) < 0.02  # seed 000 Table III: road N(0.303, 0.087)
        world = (np.c_[rec.points[:, :3], np.ones(n)] @ (t_world_velo0 @ rec.pose).T)[:, :3]
        road = rec.semantic == 40
        assert np.abs(world[road, 2]).max() < 0.02  # ground points stay on z = 0
        for raw, (c, s) in boxes.items():
            on = rec.semantic == raw
            seen[raw] += on.sum()
            if on.any():
                assert np.abs(_box_distance(world[on], np.asarray(c), s)).max() < 0.02
                assert np.all(rec.instance[on] == (11 if raw == 50 else 12))
    assert seen[50] > 100 and seen[10] > 50
    cfg = yaml.safe_load((tmp_path / "semantic-kitti.yaml").read_text())
    assert abs(sum(cfg["content"].values()) - 1.0) < 1e-9 and cfg["content"][40] > 0.5
    assert cfg["split"]["valid"] == [5]


def test_same_seed_gives_identical_bytes(test_spec, tmp_path):
    for out in ("a", "b"):
        write_sequence(_static_scene(), test_spec, tmp_path / out,
                       SequenceOptions(frames=2, threads=2, range_image=True, ply=True), progress=False)
    files = sorted(p.relative_to(tmp_path / "a") for p in (tmp_path / "a").rglob("*") if p.is_file())
    assert len(files) >= 2 * 5 + 5
    assert files == sorted(p.relative_to(tmp_path / "b") for p in (tmp_path / "b").rglob("*") if p.is_file())
    for f in files:
        assert filecmp.cmp(tmp_path / "a" / f, tmp_path / "b" / f, shallow=False), f


def test_rerun_with_fewer_frames_removes_stale_scans(test_spec, tmp_path):
    write_sequence(_static_scene(), test_spec, tmp_path, SequenceOptions(frames=3, threads=1, bev=False),
                   progress=False)
    write_sequence(_static_scene(), test_spec, tmp_path, SequenceOptions(frames=2, threads=1, bev=False),
                   progress=False)
    seq = sk.Sequence(tmp_path, 0)
    assert seq.frames == [0, 1] and len(seq.cam_poses) == 2
    assert not any(Path(tmp_path).rglob(".tmp-*"))
