"""``urbangen generate``: the whole dataset of a spec, resumable.

Stages, each skipped when its output is already complete:

1. LiDAR: one SemanticKITTI sequence (``lidar/sequences/NN``), every scan sharing its
   frame's weather draw (:func:`generator.weather.lidar_combination`). Cheap and
   byte-deterministic, so it is rewritten whole unless ``lidar_meta.json`` matches the plan.
2. Images: every frame in every planned weather x time combination, and the KITTI stereo
   pair of every ``sensors.stereo.every``-th scan (:mod:`generator.jobs.stereo`), on an
   executor (local spawned processes or Ray); a frame is done when all its metadata JSONs
   exist, a pair when its ``image_3`` PNG does.
3. OpenLABEL per sequence, then statistics.

The manifest is rewritten after every frame. Everything is written atomically, so a run
killed at any moment resumes to exactly the files of an uninterrupted run.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import shutil
import time
from pathlib import Path

from generator.atomic import clean_temporaries
from generator.jobs import manifest as mf
from generator.jobs.executors import make_jobs, run_jobs
from generator.jobs.plan import Plan
from generator.jobs.stereo import pair_done, stereo_frames

log = logging.getLogger(__name__)


@dataclasses.dataclass
class GenerateOptions:
    """Options of one ``generate`` run (validated by the command)."""

    out: Path
    plan: Plan
    workers: int = 1
    executor: str = "local"
    ray_address: str | None = None


def lidar_done(out: Path, plan: Plan, spec) -> bool:
    meta = out / "lidar" / "sequences" / plan.sequence / "lidar_meta.json"
    if not meta.exists():
        return False
    try:
        m = json.loads(meta.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError):
        return False
    return m.get("scene", {}).get("spec_hash") == spec.spec_hash and m.get("frames") == len(plan.frames)


def images_done(out: Path, plan: Plan) -> list[int]:
    """Frames whose every planned image is complete on disk."""
    images = out / "images"
    return [k for k in plan.frames if all((images / f"{n}.json").exists() for n in plan.images_of(k))]


def write_lidar(spec, cfg, out: Path, plan: Plan, scene=None) -> dict:
    from generator.layout.assemble import build_scene
    from generator.jobs.lidar_sequence import SequenceOptions, write_dataset_label_config, write_sequence

    scene = build_scene(spec) if scene is None else scene
    opts = SequenceOptions(frames=len(plan.frames), sequence=plan.sequence, resolution=cfg.resolution,
                           render_config=cfg.name, weather=True)
    meta = write_sequence(scene, spec, out / "lidar", opts)
    write_dataset_label_config(out / "lidar")
    return meta


def run_generate(spec, cfg, opts: GenerateOptions) -> dict:
    """Plan, render, scan and write a dataset into ``opts.out``; return the run record."""
    out, plan = Path(opts.out), opts.plan
    t0 = time.perf_counter()
    new = mf.new_manifest(spec, cfg, plan, opts.executor)
    old = mf.load(out)
    manifest = new
    if old is not None:
        mf.check_compatible(old, new, out)
        manifest = mf.merge_plan(old, plan)
        plan = Plan.from_dict(manifest["plan"])
    out.mkdir(parents=True, exist_ok=True)
    removed = clean_temporaries(out)
    shutil.rmtree(out / ".scratch", ignore_errors=True)
    if removed:
        log.info("removed %d unfinished temporary files of an interrupted run", removed)
    run = {"started": time.strftime("%Y-%m-%dT%H:%M:%S%z"), "executor": opts.executor, "workers": opts.workers}

    scenes: list = []

    def scene():
        """The spec's scene, built at most once in this process (LiDAR and OpenLABEL share it)."""
        if not scenes:
            from generator.layout.assemble import build_scene

            scenes.append(build_scene(spec))
        return scenes[0]

    if not lidar_done(out, plan, spec):
        t = time.perf_counter()
        write_lidar(spec, cfg, out, plan, scene())
        run["lidar_s"] = round(time.perf_counter() - t, 2)
    manifest["finished"]["lidar"] = True
    mf.save(out, manifest)

    done = set(images_done(out, plan))
    manifest["finished"]["images"] = [n for k in plan.frames if k in done for n in plan.images_of(k)]
    todo = [k for k in plan.frames if k not in done]
    seq_dir = out / "lidar" / "sequences" / plan.sequence
    pairs = stereo_frames(spec, plan.frames)
    manifest["finished"]["stereo"] = [k for k in pairs if pair_done(seq_dir, k)]
    stereo_todo = [k for k in pairs if k not in manifest["finished"]["stereo"]]
    if todo or stereo_todo:
        jobs = make_jobs(spec, cfg, out, todo, plan.combos, opts.workers, stereo_todo, seq_dir)

        def on_frame(index, payload: dict) -> None:
            manifest["finished"]["images"] += list(payload["images"])
            if "stereo" in payload:
                manifest["finished"]["stereo"].append(payload["stereo"])
            mf.save(out, manifest)

        res = run_jobs(opts.executor, jobs, len(todo) + len(stereo_todo), on_frame, opts.ray_address)
        shutil.rmtree(out / ".scratch", ignore_errors=True)
        run.update(_render_figures(res, len(todo), len(plan.combos)))
        run["stereo_pairs_rendered"] = len(stereo_todo)

    from generator.jobs.finish import write_openlabel, write_stats

    write_openlabel(spec, out, plan, scene())
    manifest["finished"]["openlabel"] = True
    write_stats(out)
    manifest["finished"]["stats"] = True
    run["wall_s"] = round(time.perf_counter() - t0, 2)
    manifest["runs"] = manifest.get("runs", []) + [run]
    mf.save(out, manifest)
    return run


def _render_figures(res, frames: int, per_frame: int) -> dict:
    """Throughput and where the workers' time went."""
    workers = res.done
    busy = sum(w["setup_s"] + w["frames_s"] for w in workers)
    cycles = sum(w["cycles_rgb_s"] for w in workers)
    rss = [(msg["frames_done"], msg["rss_mb"]) for msg in res.frame_seconds.values()]
    return {
        "render_wall_s": round(res.wall_s, 2),
        "frames_rendered": frames,
        "images_rendered": frames * per_frame,
        "frames_per_hour": round(3600.0 * frames / res.wall_s, 2) if res.wall_s else None,
        "images_per_hour": round(3600.0 * frames * per_frame / res.wall_s, 1) if res.wall_s else None,
        "worker_setup_s": [round(w["setup_s"], 2) for w in workers],
        "cycles_rgb_s": round(cycles, 2),
        "share_outside_rgb_sampling": round(1.0 - cycles / busy, 4) if busy else None,
        "worker_rss_mb": [round(w["rss_mb"], 1) for w in workers],
        "worker_max_rss_mb": [round(w["max_rss_mb"], 1) for w in workers],
        "rss_by_frames_done": sorted(rss),
    }
