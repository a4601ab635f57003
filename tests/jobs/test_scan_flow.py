"""Scene-flow side files: written with every scan but the last, and the same bytes when remade from the files."""

from __future__ import annotations

import json

import numpy as np
import pytest

from generator.dataset import Dataset
from generator.formats import semantickitti as sk
from generator.jobs.lidar_sequence import SequenceOptions, write_sequence
from generator.jobs.scan_flow import write_sequence_flow
from generator.lidar.sensors import sensor_for_spec
from generator.motion.scene_flow import scene_flow
from generator.world.rig import Rig

SWEEPS = 4


@pytest.fixture(scope="module")
def traffic_spec(root):
    from generator.spec.load import parse_spec

    doc = json.loads((root / "scenes" / "test_town.json").read_text())
    doc["traffic"] = {"cars_per_km": 40, "pedestrians_per_100m": 2.0}
    return parse_spec(doc, "test_town+traffic")


@pytest.fixture(scope="module")
def sequence(tmp_path_factory, traffic_spec):
    from generator.layout import build_scene
    from generator.traffic.build import build_world

    root = tmp_path_factory.mktemp("scanflow")
    scene = build_scene(traffic_spec)
    world = build_world(traffic_spec, scene, SWEEPS * 0.1 + 0.2)
    write_sequence(scene, traffic_spec, root / "lidar", SequenceOptions(frames=SWEEPS), world=world, progress=False)
    return root, world


def test_every_scan_but_the_last_has_its_scene_flow(sequence):
    root, world = sequence
    files = sorted(p.name for p in (root / "lidar/sequences/00/scene_flow").iterdir())
    assert files == [f"{j:06d}.bin" for j in range(SWEEPS - 1)]
    ds = Dataset(root)
    assert ds.scene_flow(SWEEPS - 1) is None
    obj, flag = ds.scene_flow(1, ego_motion=False)
    inst = ds.scan(1).instance
    on_actor = np.isin(inst, [a.instance_id for a in world.actors])
    assert on_actor.any() and (obj[~on_actor] == 0).all() and np.abs(obj[on_actor]).max() > 0.05
    meta = json.loads((root / "lidar/sequences/00/lidar_meta.json").read_text())
    assert meta["scene_flow"]["dt_s"] == 0.1 and "flag" in meta["scene_flow"]["layout"]


def test_the_reader_gives_the_flow_with_ego_motion(sequence, traffic_spec):
    root, world = sequence
    ds = Dataset(root)
    scan = ds.scan(1)
    rig = Rig.from_world(traffic_spec, world)
    sensor = sensor_for_spec(traffic_spec)
    times = ds.scan(1).time  # sweep start
    tau = np.fromfile(root / "lidar/sequences/00/point_times/000001.bin", "<f4")
    col = np.rint(tau.astype(np.float64) * sensor.azimuth_steps * sensor.rotation_hz).astype(np.int64)
    _, expected = scene_flow(scan.xyz, scan.instance, col, sensor.column_time(), times, 0.1, rig, world.actors)
    got, _ = ds.scene_flow(1)
    np.testing.assert_allclose(got, expected, atol=2e-4)


def test_remade_from_the_files_it_is_the_same_bytes(sequence, traffic_spec, tmp_path):
    root, world = sequence
    seq = sk.Sequence(root / "lidar", "00")
    n = write_sequence_flow(seq, tmp_path, Rig.from_world(traffic_spec, world), world, sensor_for_spec(traffic_spec),
                            traffic_spec.sensors.lidar.motion_skew)
    assert n == SWEEPS - 1
    for j in range(SWEEPS - 1):
        name = f"scene_flow/{j:06d}.bin"
        assert (tmp_path / name).read_bytes() == (seq.dir / name).read_bytes()
