"""``urbangen export nuscenes``: what nuscenes-devkit itself reads from the export agrees with the dataset."""

from __future__ import annotations

import json

import numpy as np
import pytest

from generator import cli
from generator.formats import nuscenes as nu
from generator.formats import semantickitti as sk
from generator.formats.box_file import read_box_file

pytest.importorskip("nuscenes")

VERSION = "v1.0-urbangen"


@pytest.fixture(scope="module")
def nusc(nuscenes_traffic):
    from nuscenes import NuScenes

    return NuScenes(version=VERSION, dataroot=str(nuscenes_traffic), verbose=False)


@pytest.fixture(scope="module")
def frozen_export(frozen_detection_dataset, tmp_path_factory):
    from nuscenes import NuScenes

    out = tmp_path_factory.mktemp("nus_frozen") / "nus"
    assert cli.main(["export", "nuscenes", str(frozen_detection_dataset), str(out)]) == 0
    return NuScenes(version=VERSION, dataroot=str(out), verbose=False)


def _shift(nusc, root) -> np.ndarray:
    """world -> global of the scene: the first ego pose against the dataset's own."""
    from generator.imaging import meta_fields as md
    from generator.world.rig import invert, mount

    meta = json.loads((root / "lidar" / "sequences" / "00" / "lidar_meta.json").read_text())
    T_world_lidar = md.sweep_poses(meta, "meta")[0][1][0]
    T_ego_lidar = mount(meta["mount"]["lidar_xyz_m"], meta["mount"]["lidar_rpy_deg"])
    first = nusc.get("sample_data", nusc.sample[0]["data"]["LIDAR_TOP"])
    T_global_ego = _pose(nusc.get("ego_pose", first["ego_pose_token"]))
    return T_global_ego @ invert(T_world_lidar @ invert(T_ego_lidar))


def _pose(rec) -> np.ndarray:
    from pyquaternion import Quaternion

    T = np.eye(4)
    T[:3, :3] = Quaternion(rec["rotation"]).rotation_matrix
    T[:3, 3] = rec["translation"]
    return T


def _track_of(nusc, ann) -> int:
    scene = nusc.get("scene", nusc.get("sample", ann["sample_token"])["scene_token"])["name"]
    for tid in range(1, 65536):   # tokens are named by (scene, "instance", track id)
        if nu.token(scene, "instance", tid) == ann["instance_token"]:
            return tid
    raise AssertionError("instance token of no track id")


def test_the_devkit_loads_every_sweep_and_the_key_frames_carry_the_box_records(nusc, traffic_detection_dataset):
    root, _ = traffic_detection_dataset
    bf = read_box_file(root / "boxes" / "00.npz")
    lidar = [d for d in nusc.sample_data if d["channel"] == "LIDAR_TOP"]
    assert len(lidar) == len(bf.sweeps) == 11 and len(nusc.sample) == 3
    assert len(nusc.sample_annotation) == sum(len(bf.records(j)) for j in (0, 5, 10))
    for d in lidar:
        assert (nusc.get_sample_data_path(d["token"])).endswith(".pcd.bin")
        assert ("samples/" if d["is_key_frame"] else "sweeps/") in d["filename"]


def test_round_trip_annotations_are_the_box_records_in_the_global_frame(nusc, traffic_detection_dataset):
    from pyquaternion import Quaternion

    root, _ = traffic_detection_dataset
    bf = read_box_file(root / "boxes" / "00.npz")
    S = _shift(nusc, root)
    recs = {(r.track_id, j): r for j in (0, 5, 10) for r in bf.records(j)}
    keys = [s["token"] for s in nusc.sample]
    for a in nusc.sample_annotation:
        r = recs[(_track_of(nusc, a), 5 * keys.index(a["sample_token"]))]
        assert np.allclose(a["translation"], S[:3, :3] @ r.center + S[:3, 3], atol=1e-9)
        assert np.allclose(a["size"], [r.size[1], r.size[0], r.size[2]])
        assert abs(np.angle(np.exp(1j * (Quaternion(a["rotation"]).yaw_pitch_roll[0] - r.yaw)))) < 1e-9
        assert a["num_lidar_pts"] == r.num_lidar_pts >= 1
        assert nusc.get("attribute", a["attribute_tokens"][0])["name"] == r.attribute


def test_every_instance_point_lies_in_its_box_as_the_devkit_moves_them(nusc, traffic_detection_dataset):
    """The key frame's .pcd.bin through the devkit's calibrated_sensor and ego_pose: each box holds the points of
    its thing (the .pcd.bin rows are the scan's rows, so the .label file names them)."""
    from nuscenes.utils.data_classes import LidarPointCloud
    from nuscenes.utils.geometry_utils import points_in_box

    root, _ = traffic_detection_dataset
    seq = sk.Sequence(root / "lidar", "00")
    bf = read_box_file(root / "boxes" / "00.npz")
    checked = 0
    for k, sample in enumerate(nusc.sample):
        sd = nusc.get("sample_data", sample["data"]["LIDAR_TOP"])
        pc = LidarPointCloud.from_file(nusc.get_sample_data_path(sd["token"]))
        pc.transform(_pose(nusc.get("calibrated_sensor", sd["calibrated_sensor_token"])))
        pc.transform(_pose(nusc.get("ego_pose", sd["ego_pose_token"])))
        _, inst = sk.read_labels(seq.label_path(5 * k))
        assert pc.points.shape[1] == len(inst)
        by_track = {r.track_id: r.instance_ids for r in bf.records(5 * k)}
        for tok in sample["anns"]:
            box = nusc.get_box(tok)
            box.wlh = box.wlh + 0.1                     # 5 cm around: points fired a few ms off the box's instant
            mine = np.isin(inst, by_track[_track_of(nusc, nusc.get("sample_annotation", tok))])
            inside = points_in_box(box, pc.points[:3, mine])
            assert inside.mean() >= 0.99, (tok, inside.mean())
            checked += 1
    assert checked == len(nusc.sample_annotation)


def test_ten_sweeps_accumulate_and_static_things_stay_in_their_boxes(nusc):
    from nuscenes.utils.data_classes import LidarPointCloud

    sample = nusc.sample[-1]
    pc, times = LidarPointCloud.from_file_multisweep(nusc, sample, "LIDAR_TOP", "LIDAR_TOP", nsweeps=10)
    assert np.allclose(np.unique(np.round(times, 3)), np.arange(10) * 0.1)
    _, boxes, _ = nusc.get_sample_data(sample["data"]["LIDAR_TOP"])     # boxes in the sensor frame
    parked = [b for b in boxes if nusc.get("attribute", nusc.get("sample_annotation", b.token)["attribute_tokens"][0])
              ["name"] == "vehicle.parked"]
    assert parked
    for b in parked:   # a parked car's points from all ten sweeps pile up inside its box (ego motion undone)
        local = b.rotation_matrix.T @ (pc.points[:3] - b.center[:, None])
        w, length, h = b.wlh
        above = local[2] > -h / 2 + 0.3                     # off the ground and kerb
        shell = above & (np.abs(local[0]) <= length / 2 + 0.3) & (np.abs(local[1]) <= w / 2 + 0.3) & (local[2] <= h / 2)
        inside = above & np.all(np.abs(local) <= np.array([[length], [w], [h]]) / 2 + 0.02, axis=0)   # exact boxes:
        assert inside.sum() >= 0.99 * shell.sum() > 0                                           # float32 on faces


def test_velocities_the_devkit_derives_match_the_worlds(nusc, traffic_detection_dataset):
    root, _ = traffic_detection_dataset
    bf = read_box_file(root / "boxes" / "00.npz")
    S = _shift(nusc, root)
    middle = nusc.sample[1]
    moving = 0
    for tok in middle["anns"]:
        a = nusc.get("sample_annotation", tok)
        v = nusc.box_velocity(tok)[:2]
        r = next(r for r in bf.records(5) if r.track_id == _track_of(nusc, a))
        truth = (S[:3, :3] @ r.velocity)[:2]
        if np.all(np.isfinite(v)):
            assert np.linalg.norm(v - truth) <= 0.4 + 0.1 * np.linalg.norm(truth), (a["category_name"], v, truth)
            moving += np.linalg.norm(truth) > 1.0
    assert moving >= 2


def test_attributes_visibility_and_categories(nusc, frozen_export):
    names = {nusc.get("attribute", a["attribute_tokens"][0])["name"] for a in nusc.sample_annotation}
    assert {"vehicle.moving", "vehicle.parked", "cycle.with_rider", "pedestrian.moving"} <= names
    cats = {a["category_name"] for a in nusc.sample_annotation}
    assert {"vehicle.car", "vehicle.truck", "vehicle.bicycle", "vehicle.motorcycle", "human.pedestrian.adult"} <= cats
    seen = {a["visibility_token"] for a in frozen_export.sample_annotation}
    assert seen - {"1"} and seen <= {"1", "2", "3", "4"}       # boxes in image_2 get its visibility bins


def test_points_are_nuscenes_lidar_top_frame_with_intensity_0_255_and_rings(nusc, traffic_detection_dataset):
    root, _ = traffic_detection_dataset
    sd = nusc.get("sample_data", nusc.sample[0]["data"]["LIDAR_TOP"])
    rows = np.fromfile(nusc.get_sample_data_path(sd["token"]), np.float32).reshape(-1, 5)
    raw = sk.read_scan(root / "lidar" / "sequences" / "00" / "velodyne" / "000000.bin")
    assert len(rows) == len(raw)
    assert np.allclose(rows[:, 3], raw[:, 3] * 255, atol=1e-3) and rows[:, 3].max() > 1
    ring = rows[:, 4]
    assert np.array_equal(ring, np.round(ring)) and ring.min() >= 0 and ring.max() <= 63
    elevation = np.arctan2(rows[:, 2], np.hypot(rows[:, 0], rows[:, 1]))
    far = np.hypot(rows[:, 0], rows[:, 1]) > 10
    assert np.corrcoef(ring[far], elevation[far])[0, 1] > 0.9            # ring 0 is the lowest beam
    ahead = np.hypot(rows[:, 0], rows[:, 1]) > 5
    # y forward: along the drive (the ego drives its route forward) most far points are not behind x = 0 only
    assert (rows[ahead, 1] > 0).any() and (rows[ahead, 0] > 0).any()


def test_the_map_mask_holds_every_ego_pose(nusc):
    mask = nusc.map[0]["mask"]
    xy = np.array([e["translation"][:2] for e in nusc.ego_pose])
    assert (xy > 0).all() and mask.is_on_mask(xy[:, 0], xy[:, 1]).all()


def test_cameras_are_key_frames_with_their_calibration(frozen_export, frozen_detection_dataset):
    nusc = frozen_export
    cams = [d for d in nusc.sample_data if d["sensor_modality"] == "camera"]
    assert {d["channel"] for d in cams} == {"CAM_FRONT", "CAM_FRONT_STEREO"} and all(d["is_key_frame"] for d in cams)
    meta = json.loads((frozen_detection_dataset / "lidar" / "sequences" / "00" / "passes_2" / "000010.json")
                      .read_text())
    front = [d for d in cams if d["channel"] == "CAM_FRONT"]
    assert len(front) == 3
    cs = nusc.get("calibrated_sensor", front[1]["calibrated_sensor_token"])
    assert np.allclose(cs["camera_intrinsic"], meta["K"])
    T_global_cam = _pose(nusc.get("ego_pose", front[1]["ego_pose_token"])) @ _pose(cs)
    shift = T_global_cam @ np.linalg.inv(np.array(meta["T_world_camera"]))
    assert np.allclose(shift[:3, :3], np.eye(3), atol=1e-9)              # global = world shifted
    _, boxes, _ = nusc.get_sample_data(front[1]["token"])
    assert boxes                                                          # the devkit finds boxes in the image


def test_cli_refuses_an_existing_export_and_a_dataset_without_boxes_or_spec(nuscenes_traffic, traffic_detection_dataset,
                                                                            tmp_path, capsys):
    root, spec = traffic_detection_dataset
    assert cli.main(["export", "nuscenes", str(root), str(nuscenes_traffic)]) == 2
    assert "v1.0-urbangen: exists" in capsys.readouterr().err
    bare = tmp_path / "bare"
    bare.mkdir()
    (bare / "lidar").symlink_to(root / "lidar")                          # the scans, no box file, no manifest
    assert cli.main(["export", "nuscenes", str(bare), str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--spec" in err[0] and not (tmp_path / "out").exists()
