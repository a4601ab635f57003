"""A town's products as tasks (:mod:`generator.jobs.town_job`): the LiDAR sequence a worker casts is the
parent-side cast of before, byte for byte."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from generator.jobs.frameset import FrameSet
from generator.jobs.plan import Plan
from kits.paths import ROOT


@pytest.fixture(scope="module")
def traffic_spec(tmp_path_factory):
    from generator.spec import load_spec

    doc = json.loads((ROOT / "scenes" / "test_town.json").read_text())
    doc["traffic"] = {"cars_per_km": 20, "pedestrians_per_100m": 2}  # the worker must build the same world
    path = tmp_path_factory.mktemp("spec") / "traffic_town.json"
    path.write_text(json.dumps(doc))
    return load_spec(path)


def _tree(root: Path) -> dict[str, bytes]:
    return {str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


@pytest.mark.slow
def test_a_towns_lidar_cast_by_a_worker_is_the_parent_side_cast(traffic_spec, tmp_path):
    from generator.jobs.dispatch import FixedSource, run_tasks
    from generator.jobs.drive import plan_drive
    from generator.jobs.lidar_sequence import SequenceOptions, write_dataset_label_config, write_sequence
    from generator.jobs.pool import LocalExecutor
    from generator.jobs.tasks import Task
    from generator.jobs.town_job import TownJob
    from generator.layout import build_scene
    from generator.spec.render import load_render_config

    spec, cfg = traffic_spec, load_render_config("test")
    plan = Plan(FrameSet.span(0, 2), (("day", "clear"),), "00")
    # before per-town jobs, generate cast every town in the parent like this (jobs/generate.py write_lidar)
    scene = build_scene(spec)
    drive = plan_drive(spec, scene, plan.frames, 0)
    assert drive.world.actors  # a world in time: the worker has to simulate the same traffic
    opts = SequenceOptions(frames=drive.sweeps, sequence="00", resolution=cfg.resolution, render_config=cfg.name,
                           weather=True, image_frames=tuple(drive.image_frames))
    write_sequence(scene, spec, tmp_path / "parent" / "lidar", opts, world=drive.world, progress=False)
    # now: a task on a spawned worker (one cast thread where the parent used every core)
    job = TownJob(spec, cfg, str(tmp_path / "worker"), plan, 0, ("lidar",), threads=1)
    source = FixedSource([Task(0, "scan", "generator.jobs.town_job:run", job)])
    run_tasks(LocalExecutor(1), source, desc="scan")
    items = [m for m in source.messages[0] if m[0] == "item"]
    assert [(m[1], m[2]["extra"]) for m in items] == [(("town", "00", "lidar"), {"sweeps": drive.sweeps})]
    seq = Path("lidar") / "sequences" / "00"
    parent, worker = _tree(tmp_path / "parent" / seq), _tree(tmp_path / "worker" / seq)
    assert len(parent) > 4 * drive.sweeps and parent.keys() == worker.keys()
    assert [k for k in parent if parent[k] != worker[k]] == []
    # the dataset's label config is written once at the end of a run (the dataset task): the same file
    write_dataset_label_config(tmp_path / "worker" / "lidar")
    assert (tmp_path / "worker" / "lidar" / "semantic-kitti.yaml").read_bytes() == \
        (tmp_path / "parent" / "lidar" / "semantic-kitti.yaml").read_bytes()
