"""A real Ray cluster on this machine: a head and a second node, the second killed mid-run.

The run (stand-in tasks, :mod:`generator.jobs.dry`: no Blender) must finish on the head with every
item made once: the same files and the same journal as a run on the local executor.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import pytest

from generator.jobs.generate import GenerateOptions, run_generate
from generator.jobs.plan import make_plan
from kits.paths import ROOT
from kits.stand_in_run import COMBOS, spec_with_towns

pytestmark = pytest.mark.slow
FRAMES = 10


def _files(root: Path) -> dict[str, bytes]:
    return {str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*"))
            if p.is_file() and p.name != "manifest.json"}


def _run(spec, out: Path, executor: str, delay: float = 0.0, address=None) -> dict:
    from generator.spec.render import load_render_config

    opts = GenerateOptions(out, make_plan(FRAMES, combos=COMBOS), 2, executor, address, stand_in=True,
                           stand_in_delay_s=delay)
    return run_generate(spec, load_render_config("test"), opts)


def _kill_after_frames_on(node_id: str, frames: int, kill, monkeypatch) -> dict:
    """Call ``kill()`` when the parent has recorded ``frames`` frames rendered on node ``node_id`` (its
    task is then mid-run: it has more frames to go)."""
    from generator.jobs import schedule
    from generator.jobs.ray_executor import RayExecutor

    seen = {"executor": None, "frames": 0}
    events = RayExecutor.events

    def spy_events(self, timeout):
        seen["executor"] = self
        return events(self, timeout)

    on_message = schedule.RunSource.on_message

    def spy_message(self, task, msg):
        on_message(self, task, msg)
        ex = seen["executor"]
        if msg[0] == "frame" and ex is not None and ex.nodes.get(task.id) == node_id and "at" not in seen:
            seen["frames"] += 1
            if seen["frames"] == frames:
                seen["at"] = time.time()
                kill()

    monkeypatch.setattr(RayExecutor, "events", spy_events)
    monkeypatch.setattr(schedule.RunSource, "on_message", spy_message)
    return seen


def test_a_node_killed_mid_run_loses_nothing_and_duplicates_nothing(tmp_path, monkeypatch):
    ray = pytest.importorskip("ray")
    # Ray runs its workers at nice 15: beside the other pytest worker (nice 0) they would get almost no CPU
    monkeypatch.setenv("RAY_worker_niceness", "0")
    from ray.cluster_utils import Cluster

    from generator.spec import load_spec

    spec = load_spec(spec_with_towns(None, tmp_path / "spec.json"))
    reference = tmp_path / "local"
    _run(spec, reference, "local")

    cluster = Cluster(initialize_head=True, head_node_args={
        "num_cpus": 1, "include_dashboard": False,
        "_system_config": {"health_check_initial_delay_ms": 0, "health_check_period_ms": 500,
                           "health_check_failure_threshold": 3}})
    side = cluster.add_node(num_cpus=1)  # one task at a time on each node: the two render jobs run on both
    cluster.wait_for_nodes()
    path = os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])
    ray.init(address=cluster.address, log_to_driver=False, runtime_env={"env_vars": {"PYTHONPATH": path}})
    try:
        head = ray.get_runtime_context().get_node_id()
        (side_id,) = [n["NodeID"] for n in ray.nodes() if n["Alive"] and n["NodeID"] != head]
        out = tmp_path / "cluster"
        killed = _kill_after_frames_on(side_id, 2, lambda: cluster.remove_node(side, allow_graceful=False),
                                       monkeypatch)
        run = _run(spec, out, "ray", delay=0.3, address=cluster.address)
    finally:
        ray.shutdown()
        cluster.shutdown()
    assert "at" in killed, "the second node was not killed mid-run"
    # both nodes worked, the killed one lost its task
    assert run["tasks_lost"] >= 1 and set(run["ray_nodes"]) == {head, side_id}, (str(run), head, side_id)
    assert _files(out) == _files(reference)  # nothing lost, nothing extra (no temporaries left), same journal
    assert run["frames_rendered"] == FRAMES and run["images_rendered"] == FRAMES * len(COMBOS)  # recorded once each
