"""Two towns' LiDAR sequences as tasks: one worker after the other, or two workers at once (issue 30).

Each town's scan task builds the town, simulates its traffic and casts its sequence
(:mod:`generator.jobs.town_job`), as ``generate`` runs it. Rows, in one run:

* one town on one worker (the cast on every core): the wall of one town;
* two towns on one worker, one after the other (every core each);
* two towns on two workers at once (half the cores each), as ``generate --workers 2`` runs them.

"in flight": task seconds / wall (how many towns were being worked on at once); "cores used": the
tasks' CPU seconds / wall (what the machine gave them: on a shared machine less than its cores).

    python bench/town_lidar.py --work /tmp/ug_town_lidar [--spec scenes/test_town.json] [--frames 3]
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import time
from pathlib import Path


def _spec(path: str, work: Path, every: int):
    from generator.spec import load_spec

    doc = json.loads(Path(path).read_text())
    doc.setdefault("traffic", {"cars_per_km": 20, "pedestrians_per_100m": 2})
    doc.setdefault("town", {})["redraw_every_frames"] = every
    out = work / "spec.json"
    out.write_text(json.dumps(doc))
    return load_spec(out)


def cast(spec, cfg, work: Path, towns: int, workers: int, frames: int) -> tuple[float, list[float]]:
    """Wall seconds of casting ``towns`` towns on ``workers`` local workers, and each task's LiDAR seconds."""
    from generator.jobs.dispatch import FixedSource, run_tasks
    from generator.jobs.plan import make_plan
    from generator.jobs.pool import LocalExecutor
    from generator.jobs.tasks import Task
    from generator.jobs.town_job import TownJob
    from generator.jobs.towns import TownPlan

    shutil.rmtree(work / "out", ignore_errors=True)
    plan = TownPlan(spec, make_plan(frames * towns, combos=[("day", "clear")]))
    threads = max(1, (os.cpu_count() or 1) // workers)
    tasks = [Task(i, "scan", "generator.jobs.town_job:run",
                  TownJob(run.spec, cfg, str(work / "out"), run.plan, run.first, ("lidar",), threads))
             for i, run in enumerate(plan)]
    source = FixedSource(tasks)
    t = time.perf_counter()
    run_tasks(LocalExecutor(workers), source, desc=f"{towns} towns on {workers} workers")
    wall = time.perf_counter() - t
    done = [m[1] for msgs in source.messages.values() for m in msgs if m[0] == "done"]
    return wall, [(d["wall_s"], d["cpu_s"]) for d in done]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--work", type=Path, required=True, help="scratch folder")
    ap.add_argument("--spec", default="scenes/test_town.json", help="spec (traffic added if it has none)")
    ap.add_argument("--frames", type=int, default=3, help="image frames per town (its drive)")
    a = ap.parse_args()
    from generator.spec.render import load_render_config

    a.work.mkdir(parents=True, exist_ok=True)
    spec, cfg = _spec(a.spec, a.work, a.frames), load_render_config("test")
    print(f"{Path(a.spec).name} with traffic, {a.frames} image frames a town, {os.cpu_count()} cores; a task per town "
          "(scene, traffic, LiDAR sequence)")
    print(f"{'case':>34}{'wall s':>9}{'tasks: wall s (CPU s)':>28}{'in flight':>11}{'cores used':>12}")
    rows = [("1 town, 1 worker", 1, 1), ("2 towns, 1 worker (one by one)", 2, 1),
            ("2 towns, 2 workers (parallel)", 2, 2)]
    for name, towns, workers in rows:
        wall, tasks = cast(spec, cfg, a.work, towns, workers, a.frames)
        per = ", ".join(f"{w:.1f} ({c:.1f})" for w, c in tasks)
        print(f"{name:>34}{wall:>9.1f}{per:>28}{sum(w for w, _ in tasks) / wall:>11.2f}"
              f"{sum(c for _, c in tasks) / wall:>12.2f}", flush=True)
    shutil.rmtree(a.work / "out", ignore_errors=True)


if __name__ == "__main__":
    main()
