"""A town built once per run (:mod:`generator.jobs.town_cache`): a task reads only the town it would have
built, and a read town makes the bytes a built one makes."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from generator.jobs import town_cache
from generator.jobs.frameset import FrameSet
from generator.jobs.plan import Plan
from kits.paths import ROOT


def test_a_kept_town_is_read_back_for_the_same_spec_frames_and_first(tmp_path):
    path = town_cache.town_file(tmp_path, "00")
    town_cache.save(path, {"seed": 1}, FrameSet.span(0, 3), 0, {"scene": [1.5, 2]}, ("drive", 7))
    assert town_cache.load(path, {"seed": 1}, range(3), 0) == ({"scene": [1.5, 2]}, ("drive", 7))


@pytest.mark.parametrize("spec, frames, first", [({"seed": 2}, range(3), 0), ({"seed": 1}, range(4), 0),
                                                 ({"seed": 1}, range(3), 1)])
def test_a_kept_town_of_another_spec_or_frames_is_not_read(tmp_path, spec, frames, first):
    path = town_cache.town_file(tmp_path, "00")
    town_cache.save(path, {"seed": 1}, range(3), 0, "scene", "drive")
    assert town_cache.load(path, spec, frames, first) is None


def test_a_torn_or_missing_file_means_build_the_town(tmp_path):
    path = town_cache.town_file(tmp_path, "00")
    assert town_cache.load(path, {}, range(1), 0) is None
    assert town_cache.load("", {}, range(1), 0) is None
    town_cache.save(path, {}, range(1), 0, "scene", "drive")
    path.write_bytes(path.read_bytes()[:20])
    assert town_cache.load(path, {}, range(1), 0) is None
    town_cache.discard(path)
    assert not path.exists()


def test_a_library_pickles_and_builds_on_after_it(tmp_path):
    import pickle

    from generator.layout.placement.prototypes import Library

    lib = Library(5)
    car = lib.variant("car", 0)
    again = pickle.loads(pickle.dumps(lib))
    assert again.protos["car_v0"].mesh.vertices.tobytes() == car.mesh.vertices.tobytes()
    assert again.variant("car", 1).mesh.vertices.tobytes() == lib.variant("car", 1).mesh.vertices.tobytes()


def _tree(root: Path) -> dict[str, bytes]:
    return {str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


@pytest.mark.slow
def test_a_scan_task_reading_the_kept_town_casts_what_one_building_it_casts(tmp_path):
    """The parent's town (traffic included), pickled and read by a spawned task, casts the same sequence."""
    from generator.jobs.dispatch import FixedSource, run_tasks
    from generator.jobs.drive import plan_drive
    from generator.jobs.pool import LocalExecutor
    from generator.jobs.tasks import Task
    from generator.jobs.town_job import TownJob
    from generator.layout import build_scene
    from generator.spec import load_spec
    from generator.spec.render import load_render_config

    doc = json.loads((ROOT / "scenes" / "test_town.json").read_text())
    doc["traffic"] = {"cars_per_km": 20, "pedestrians_per_100m": 2}
    (tmp_path / "traffic_town.json").write_text(json.dumps(doc))
    spec, cfg = load_spec(tmp_path / "traffic_town.json"), load_render_config("test")
    plan = Plan(FrameSet.span(0, 2), (("day", "clear"),), "00")
    scene = build_scene(spec)
    drive = plan_drive(spec, scene, plan.frames, 0)
    kept = town_cache.town_file(tmp_path / "read", "00")
    town_cache.save(kept, spec, plan.frames, 0, scene, drive)
    built_file = town_cache.town_file(tmp_path / "built", "00")
    jobs = [TownJob(spec, cfg, str(tmp_path / "read"), plan, 0, ("lidar",), 1, str(kept)),
            TownJob(spec, cfg, str(tmp_path / "built"), plan, 0, ("lidar",), 1, str(built_file))]
    source = FixedSource([Task(i, "scan", "generator.jobs.town_job:run", job) for i, job in enumerate(jobs)])
    run_tasks(LocalExecutor(1), source, desc="scan")
    assert built_file.is_file()  # the task that built its town kept it for the town's next tasks
    seq = Path("lidar") / "sequences" / "00"
    read, built = _tree(tmp_path / "read" / seq), _tree(tmp_path / "built" / seq)
    assert len(read) > 4 * drive.sweeps and read.keys() == built.keys()
    assert [k for k in read if read[k] != built[k]] == []
