"""nuScenes v1.0 records (pure): nuScenes' frame conventions, key frames, links and tokens."""

from __future__ import annotations

import numpy as np
import pytest

from generator.formats import nuscenes as nu
from generator.geometry.transforms import mount


def _sweeps(n: int) -> list[nu.Sweep]:
    return [nu.Sweep(j, 1000 + 100_000 * j, np.eye(4), f"s/{j}.pcd.bin") for j in range(n)]


def _scene(n: int = 11, annotations=()) -> nu.SceneInput:
    return nu.SceneInput("town-00", "test", "town", mount((0, 0, 1.73), (0, 0, 0)), _sweeps(n), list(annotations))


def test_an_unturned_mount_is_nuscenes_own_lidar_top_rotation():
    b = nu.TableBuilder()
    b.add_scene(_scene())
    cs = b.tables()["calibrated_sensor"][0]
    assert np.allclose(cs["rotation"], [np.sqrt(0.5), 0, 0, -np.sqrt(0.5)])   # nuScenes' LIDAR_TOP value
    assert cs["translation"] == [0.0, 0.0, 1.73] and cs["camera_intrinsic"] == []


def test_pcd_rows_put_forward_on_y_right_on_x_and_scale_intensity_and_rings():
    xyz = np.array([[10.0, 0.0, 1.0], [0.0, 5.0, -1.0]])           # ahead; to the left (urbangen LiDAR frame)
    rows = nu.pcd_rows(xyz, np.array([1.0, 0.5]), np.array([0, 63]), 64)
    assert rows.dtype == np.dtype("<f4") and rows.shape == (2, 5)
    assert np.allclose(rows[0, :3], [0.0, 10.0, 1.0]) and np.allclose(rows[1, :3], [-5.0, 0.0, -1.0])
    assert np.allclose(rows[:, 3], [255.0, 127.5])                   # nuScenes' 0-255 intensity
    assert np.allclose(rows[:, 4], [63, 0])                          # ring 0 = the lowest beam


def test_key_frames_every_fifth_sweep_and_sweeps_belong_to_the_nearest_sample():
    b = nu.TableBuilder()
    b.add_scene(_scene(12))
    t = b.tables()
    samples = t["sample"]
    assert [s["timestamp"] for s in samples] == [1000, 1000 + 500_000, 1000 + 1_000_000]
    assert samples[0]["prev"] == "" and samples[0]["next"] == samples[1]["token"] and samples[-1]["next"] == ""
    by_tok = {s["token"]: i for i, s in enumerate(samples)}
    data = t["sample_data"]
    assert [d["is_key_frame"] for d in data] == [j % 5 == 0 for j in range(12)]
    assert [by_tok[d["sample_token"]] for d in data] == [0, 0, 0, 1, 1, 1, 1, 1, 2, 2, 2, 2]
    assert all(a["next"] == b_["token"] and b_["prev"] == a["token"] for a, b_ in zip(data, data[1:], strict=False))
    assert {d["token"] for d in data} == {e["token"] for e in t["ego_pose"]}


def test_annotations_link_per_instance_in_wlh_order_with_yaw_quaternions():
    anns = [nu.Annotation(j, 7, "vehicle.car", "vehicle.moving", np.array([j, 0.0, 1.0]), np.array([4.5, 1.8, 1.5]),
                          np.pi / 2, 100) for j in (0, 5, 10)]
    b = nu.TableBuilder()
    b.add_scene(_scene(11, anns))
    t = b.tables()
    recs = t["sample_annotation"]
    assert [r["size"] for r in recs] == [[1.8, 4.5, 1.5]] * 3
    assert np.allclose(recs[0]["rotation"], [np.sqrt(0.5), 0, 0, np.sqrt(0.5)])
    assert recs[0]["prev"] == "" and recs[0]["next"] == recs[1]["token"] and recs[2]["next"] == ""
    inst = t["instance"][0]
    assert inst["nbr_annotations"] == 3 and inst["first_annotation_token"] == recs[0]["token"]
    assert inst["last_annotation_token"] == recs[2]["token"]


def test_tokens_are_32_hex_and_the_same_input_gives_the_same_tables():
    def build():
        b = nu.TableBuilder()
        b.add_scene(_scene(6))
        return b.tables()

    a, b = build(), build()
    assert a == b
    tok = a["sample"][0]["token"]
    assert len(tok) == 32 and int(tok, 16) >= 0


def test_an_annotation_of_a_sweep_that_is_no_key_frame_or_an_unknown_category_is_refused():
    bad = nu.Annotation(3, 1, "vehicle.car", "", np.zeros(3), np.ones(3), 0.0, 1)
    with pytest.raises(ValueError, match="no key frame"):
        nu.TableBuilder().add_scene(_scene(6, [bad]))
    bad = nu.Annotation(0, 1, "vehicle.hovercraft", "", np.zeros(3), np.ones(3), 0.0, 1)
    with pytest.raises(ValueError, match="unknown category"):
        nu.TableBuilder().add_scene(_scene(6, [bad]))
