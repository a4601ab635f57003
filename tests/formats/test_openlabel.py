"""OpenLABEL 1.0 boxes of a LiDAR sequence: schema-valid, and every cuboid holds its object's points."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from generator.cli import main
from generator.detection import subjects
from generator.formats import semantickitti as sk
from generator.formats.openlabel import SCHEMA_PATH, cuboid_contains, cuboid_val, validate_openlabel, write_openlabel
from generator.formats.point_sidecars import TIMES_DIR, read_sidecar
from generator.fusion.projection import deskew, transform
from generator.labels import class_table
from generator.labels.detection import detection_classes
from generator.world import rig
from generator.world.scene import OrientedBox
from kits.paths import SHARED
from kits.sensor_kit import ideal

REFERENCE_SCHEMA = SHARED / "reference" / "openlabel_json_schema-v1.0.0.json"


@pytest.fixture(scope="module")
def town_dataset(tmp_path_factory, test_spec):
    """The test town cast for 3 frames into DIR/lidar, then ``urbangen openlabel`` on it."""
    from generator.jobs.lidar_sequence import SequenceOptions, write_sequence
    from generator.layout.assemble import build_scene

    root = tmp_path_factory.mktemp("olds")
    scene = build_scene(test_spec)
    # the ideal sensor: cuboids are checked to hold every point of their object
    write_sequence(scene, ideal(test_spec), root / "lidar", SequenceOptions(frames=3, threads=2, bev=False),
                   progress=False)
    assert main(["openlabel", test_spec.source, str(root)]) == 0
    doc = json.loads((root / "openlabel" / "00.json").read_text())
    return root, scene, doc


def test_packaged_schema_is_the_reference():
    if not REFERENCE_SCHEMA.is_file():
        pytest.skip("shared/reference not beside the checkout")
    assert json.loads(SCHEMA_PATH.read_text()) == json.loads(REFERENCE_SCHEMA.read_text())


def test_file_validates_against_the_schema(town_dataset):
    _, _, doc = town_dataset
    assert validate_openlabel(doc) == []
    ol = doc["openlabel"]
    assert ol["metadata"]["schema_version"] == "1.0.0"
    assert set(ol["coordinate_systems"]) == {"odom", "vehicle-iso8855", "lidar", "camera"}
    assert ol["coordinate_systems"]["lidar"]["parent"] == "vehicle-iso8855"
    assert set(ol["streams"]) == {"camera", "lidar"}
    assert len(ol["streams"]["camera"]["stream_properties"]["intrinsics_pinhole"]["camera_matrix"]) == 12
    assert sorted(ol["frames"], key=int) == ["0", "1", "2"]
    for f in ol["frames"].values():
        assert "vehicle-iso8855_to_odom" in f["frame_properties"]["transforms"]
    assert {o["type"] for o in ol["objects"].values()} <= set(detection_classes().boxes)
    assert any(o["type"] == "car" for o in ol["objects"].values())


def test_a_broken_document_is_refused_and_not_written(tmp_path, town_dataset):
    _, _, doc = town_dataset
    bad = json.loads(json.dumps(doc))
    bad["openlabel"]["metadata"]["schema_version"] = "0.9"
    bad["openlabel"]["frames"]["0"]["objects"]["x"] = {}
    assert len(validate_openlabel(bad)) >= 2
    with pytest.raises(ValueError, match="schema"):
        write_openlabel(tmp_path / "bad.json", bad)
    assert not (tmp_path / "bad.json").exists()


def _vehicle_points(root: Path, k: int, meta: dict, T_ego_lidar: np.ndarray):
    """Scan k de-skewed into the vehicle frame at the sweep start, with its instance ids."""
    seq = sk.Sequence(root / "lidar", "00")
    rec = seq.read(k)
    times = read_sidecar(seq.dir, TIMES_DIR, k, len(rec.points))
    sweep = meta["sweep_poses_world"]["frames"][k]
    xyz = deskew(rec.points[:, :3], times, sweep["t_s"], sweep["T_world_lidar"])
    return transform(T_ego_lidar, xyz), rec.instance


def test_every_cuboid_holds_its_objects_points_and_no_other_objects(town_dataset, test_spec):
    from generator.world.rig import Rig

    root, scene, doc = town_dataset
    ol = doc["openlabel"]
    meta = json.loads((root / "lidar" / "sequences" / "00" / "lidar_meta.json").read_text())
    min_points = ol["metadata"]["urbangen"]["min_points"]
    thing = np.array([r.thing for r in class_table().rows])
    thing_instances = {o.instance_id for o in scene.objects if o.instance_id > 0 and thing[class_table().id(o.cls)]}
    by_track = {s.track_id: s.instance_ids for s in subjects(scene)}
    checked = 0
    for key, frame in ol["frames"].items():
        xyz, inst = _vehicle_points(root, int(key), meta, Rig.from_spec(test_spec).T_ego_lidar)
        counts = np.bincount(inst, minlength=65536)
        for uid, data in frame["objects"].items():
            val = data["object_data"]["cuboid"][0]["val"]
            ids = by_track[int(uid)]
            mine = np.isin(inst, ids)
            assert data["object_data"]["num"][0]["val"] == sum(int(counts[i]) for i in ids) >= min_points
            inside = cuboid_contains(val, xyz, margin=0.02)
            assert inside[mine].all(), f"frame {key} object {uid}: {np.count_nonzero(~inside[mine])} own points outside"
            others = inside & ~mine & np.isin(inst, list(thing_instances - set(ids)))
            assert not others.any(), f"frame {key} object {uid} holds points of {np.unique(inst[others])}"
            checked += 1
        # every boxed thing with enough points is there (vehicle and rider counted together); the rest are left out
        for s in subjects(scene):
            n = sum(int(counts[i]) for i in s.instance_ids)
            assert (str(s.track_id) in frame["objects"]) == (n >= max(min_points, 1))
    assert checked >= 10


def test_cuboid_val_matches_the_world_box(rng):
    box = OrientedBox((10.0, -4.0, 0.8), (4.5, 1.9, 1.6), 0.7)
    T_world_ego = rig.ego_pose(np.array([3.0, 2.0, 0.1]), -0.4)
    val = cuboid_val(box, rig.invert(T_world_ego))
    assert np.isclose(np.linalg.norm(val[3:7]), 1.0)
    assert val[7:] == pytest.approx([4.5, 1.9, 1.6])
    pts = np.asarray(box.center) + rng.uniform(-3, 3, (2000, 3))
    in_world = box.contains(pts)
    in_vehicle = cuboid_contains(val, transform(rig.invert(T_world_ego), pts))
    assert in_world.any() and (~in_world).any()
    assert np.array_equal(in_world, in_vehicle)


def test_cli_refuses_a_sequence_of_another_spec(town_dataset, default_spec, capsys):
    root, _, _ = town_dataset
    assert main(["openlabel", default_spec.source, str(root)]) == 2
    assert "another spec" in capsys.readouterr().err


def test_cli_min_points_threshold_drops_objects(town_dataset, test_spec, tmp_path):
    root, _, doc = town_dataset
    few = sum(len(f["objects"]) for f in doc["openlabel"]["frames"].values())
    assert main(["openlabel", test_spec.source, str(root), "--min-points", "500"]) == 0
    strict = json.loads((root / "openlabel" / "00.json").read_text())
    many = sum(len(f["objects"]) for f in strict["openlabel"]["frames"].values())
    assert 0 < many < few
    for f in strict["openlabel"]["frames"].values():
        assert all(d["object_data"]["num"][0]["val"] >= 500 for d in f["objects"].values())
    main(["openlabel", test_spec.source, str(root)])  # restore the default file for other tests


@pytest.mark.parametrize("bad", ["1e308", "-1", "nan"])
def test_times_beyond_any_drive_are_one_line(town_dataset, test_spec, tmp_path, capsys, bad):
    """times.txt sets the instants the drive is asked for: a corrupted one is refused, not simulated."""
    import shutil

    root = tmp_path / "ds"
    shutil.copytree(town_dataset[0] / "lidar", root / "lidar")
    times = root / "lidar" / "sequences" / "00" / "times.txt"
    lines = times.read_text().splitlines()
    times.write_text("\n".join([lines[0], bad, *lines[2:]]) + "\n")
    capsys.readouterr()
    assert main(["openlabel", test_spec.source, str(root)]) == 2
    err = capsys.readouterr().err.strip()
    said = err.replace(str(root), "").replace("[0,", "")   # the message, not the temporary path (pytest-1..)
    assert "times.txt" in err and "\n" not in err and bad not in said
    assert not (root / "openlabel").exists()
