"""import-carla: a KITTI-CARLA town written here in the exact field layout becomes a SemanticKITTI sequence."""

from __future__ import annotations

import json

import numpy as np
import pytest
import yaml

import generator.cli as cli
from generator.formats import carla_ply
from generator.formats import semantickitti as sk
from generator.labels import class_table
from generator.world import rig
from kits.carla_town import DT, PACKETS, make_town, write_ply


@pytest.fixture(autouse=True)
def only_ours(monkeypatch):
    monkeypatch.setattr(cli, "COMMANDS", ["import_carla"])


def run(args, capsys):
    try:
        rc = cli.main(args)
    except SystemExit as e:
        rc = e.code
    return rc, capsys.readouterr()


def test_import_maps_every_tag_and_keeps_geometry_poses_instances(tmp_path, capsys):
    town, frames, poses = make_town(tmp_path)
    out = tmp_path / "kitti"
    rc, io = run(["import-carla", str(town), str(out), "--sequence", "22", "--intensity", "class_normal"], capsys)
    assert rc == 0, io.err
    assert "wrote 3 scans" in io.out
    doc = yaml.safe_load(carla_ply.TAG_FILE.read_text())["tags"]
    assert sorted(doc) == list(range(23)) and doc[10]["semantickitti"] == 10  # vehicles -> car
    seq = sk.Sequence(out, 22)
    assert len(seq) == 3
    table = class_table()
    seen_instances = set()
    for rec, v in zip(seq, frames, strict=False):
        assert np.array_equal(rec.points[:, :3], np.stack([v["x"], v["y"], v["z"]], -1))
        expected = np.array([doc[int(t)]["semantickitti"] for t in v["semantic"]])
        assert np.array_equal(rec.semantic, expected)
        assert set(np.unique(rec.semantic)) == {r["semantickitti"] for r in doc.values()}
        assert all(int(r) in table.sk_labels for r in np.unique(rec.semantic))
        assert 0 <= rec.points[:, 3].min() and rec.points[:, 3].max() <= 1
        # CARLA object ids 100000..100003 -> 1..4, the same object keeps its id in every scan
        things = np.isin(v["semantic"], [4, 10])
        assert np.all(rec.instance[~things] == 0)
        for carla_id in np.unique(v["instance"][things]):
            ours = np.unique(rec.instance[v["instance"] == carla_id])
            assert len(ours) == 1 and 1 <= ours[0] <= 4
            seen_instances.add((int(carla_id), int(ours[0])))
    assert len({c for c, _ in seen_instances}) == len(seen_instances)  # one of ours per CARLA id across scans
    # poses: sweep-start packet pose, relative to the first scan
    lidar = seq.lidar_poses()
    for k in range(3):
        expected = rig.invert(poses[0]) @ poses[k * PACKETS]
        assert np.allclose(lidar[k], expected, atol=1e-6)
    assert np.allclose(seq.times, [0.0, PACKETS * DT, 2 * PACKETS * DT], atol=1e-6)
    meta = json.loads((out / "sequences" / "22" / "lidar_meta.json").read_text())
    assert meta["processing"]["intensity"]["model"] == "class_normal" and meta["frames"] == 3
    assert meta["tag_map"]["tags"]["10"] == {"name": "vehicles", "semantickitti": 10}
    assert (out / "semantic-kitti.yaml").is_file()
    assert not [p for p in out.iterdir() if p.name.startswith(".tmp-")]


def test_class_normal_intensity_follows_the_mapped_class(tmp_path, capsys):
    town, frames, _ = make_town(tmp_path, frames=1, per_tag=4000)
    out = tmp_path / "kitti"
    assert run(["import-carla", str(town), str(out), "--sequence", "23"], capsys)[0] == 0
    rec = next(iter(sk.Sequence(out, 23)))
    road = rec.points[rec.semantic == 40, 3]
    sign = rec.points[rec.semantic == 81, 3]
    assert abs(road.mean() - 0.303) < 0.01 and abs(road.std() - 0.087) < 0.01  # Table III road
    assert sign.std() > 0.25 and (sign == 1.0).mean() > 0.05  # traffic-sign: wide, clipped at 1


def test_physical_uses_the_ply_cos_and_domain_gap_applies(tmp_path, capsys):
    town, frames, _ = make_town(tmp_path, frames=1, per_tag=2000)
    out = tmp_path / "kitti"
    rc, io = run(["import-carla", str(town), str(out), "--sequence", "24", "--intensity", "physical",
                  "--domain-gap", "seed002", "--gap-intensity", "none"], capsys)
    assert rc == 0, io.err
    rec = next(iter(sk.Sequence(out, 24)))
    v = frames[0]
    assert len(rec.points) == len(v) - round(0.1 * len(v))
    b = rec.semantic == 50  # CARLA building (tag 1)
    xyz = rec.points[b, :3]
    r = np.linalg.norm(xyz, axis=1)
    meta = json.loads((out / "sequences" / "24" / "lidar_meta.json").read_text())
    assert meta["processing"]["domain_gap"]["dropout"] == 0.1
    assert meta["scans"][0]["domain_gap"]["removed"] == round(0.1 * len(v))
    assert rec.points[:, 3].max() <= 1 and rec.points[:, 3].min() >= 0
    # I * R^2 / rho grows with the incidence cosine the PLY gave (match points to the PLY by nearest xyz)
    src = np.stack([v["x"], v["y"], v["z"]], -1)
    idx = np.argmin(((src[v["semantic"] == 1][None] - xyz[:, None]) ** 2).sum(-1), axis=1)
    cos = v["cos_angle_lidar_surface"][v["semantic"] == 1][idx]
    norm = rec.points[b, 3] * r ** 2
    far = (r > 10) & (r < 20)  # nearer than ~6 m a facade saturates at 1; far, the absolute noise dominates
    assert np.corrcoef(cos[far], norm[far])[0, 1] > 0.9


def test_without_pose_file_identity_poses(tmp_path, capsys):
    town, _, _ = make_town(tmp_path, frames=2, poses=False)
    out = tmp_path / "kitti"
    assert run(["import-carla", str(town), str(out), "--sequence", "25"], capsys)[0] == 0
    seq = sk.Sequence(out, 25)
    assert np.allclose(seq.lidar_poses(), np.eye(4)[None].repeat(2, 0))
    meta = json.loads((out / "sequences" / "25" / "lidar_meta.json").read_text())
    assert meta["poses"]["source"].startswith("identity")


def test_big_endian_and_alias_fields_read(tmp_path):
    dt = np.dtype([("x", ">f4"), ("y", ">f4"), ("z", ">f4"), ("cos", ">f4"), ("instance", ">u4"), ("semantic", ">u4")])
    v = np.zeros(5, dt)
    v["x"], v["semantic"], v["cos"] = np.arange(5), np.arange(5), 0.5
    write_ply(tmp_path / "f.ply", v, fmt="binary_big_endian", dtype=dt)
    f = carla_ply.read_frame(tmp_path / "f.ply")
    assert f["x"].tolist() == [0, 1, 2, 3, 4] and f["tag"].tolist() == [0, 1, 2, 3, 4] and np.all(f["cos"] == 0.5)
    assert np.isnan(f["timestamp"]).all()


@pytest.mark.parametrize("case, message", [
    ("tag23", "semantic tag 23 is not a CARLA 0.9.10 tag"),
    ("ascii", "PLY format 'ascii' not supported"),
    ("truncated", "(truncated)"),
    ("no_semantic", "PLY has no 'semantic' property"),
    ("no_frames", "no frames/ folder"),
    ("bad_pose", "expected 13 numbers"),
])
def test_bad_input_one_line_exit_2_nothing_written(tmp_path, capsys, case, message):
    town, frames, _ = make_town(tmp_path, frames=2)
    last = town / "generated" / "frames" / "frame_0001.ply"
    if case == "tag23":
        v = frames[1].copy()
        v["semantic"][-1] = 23
        write_ply(last, v)
    elif case == "ascii":
        last.write_bytes(last.read_bytes().replace(b"binary_little_endian", b"ascii"))
    elif case == "truncated":
        last.write_bytes(last.read_bytes()[:-10])
    elif case == "no_semantic":
        write_ply(last, frames[1][["x", "y", "z", "cos_angle_lidar_surface", "instance"]],
                  dtype=np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("cos_angle_lidar_surface", "<f4"),
                                  ("instance", "<u4")]))
    elif case == "no_frames":
        town = tmp_path / "empty_town"
        town.mkdir()
    elif case == "bad_pose":
        with open(town / "generated" / "full_poses_lidar.txt", "a") as f:
            f.write("1 2 3\n")
    out = tmp_path / "kitti"
    rc, io = run(["import-carla", str(town), str(out), "--sequence", "22"], capsys)
    assert rc == 2 and message in io.err and io.err.count("\n") == 1, io.err
    assert not out.exists()
