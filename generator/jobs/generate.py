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

The stages run town by town: one town unless ``town.redraw_every_frames`` is set, then town ``i``
(its own seed, its own drive from t = 0) makes sequence ``NN + i`` (:mod:`generator.jobs.towns`).

Before the first write, :func:`preflight` checks the whole run: the manifest of a folder
being resumed (readable, same spec, config and sequence, the merged plan), the plan's
size (:func:`generator.jobs.plan.check_plan`), the scene, sensor and intensity files the
LiDAR stage reads, the route's room for the frames, and the disk the run will write against
the free space at the output. A bad input therefore leaves no folder behind.

The manifest is rewritten after every frame. Everything is written atomically, so a run
killed at any moment resumes to exactly the files of an uninterrupted run.
"""

from __future__ import annotations

import dataclasses
import logging
import os
import shutil
import time
from pathlib import Path

from generator.atomic import clean_temporaries
from generator.errors import SpecError, UserError
from generator.imaging.paths import find_image
from generator.jobs import manifest as mf
from generator.jobs.executors import make_jobs, run_jobs
from generator.jobs.plan import MAX_FRAME_INDEX, MAX_IMAGES, Plan, check_free_space, check_plan, image_bytes, scan_bytes
from generator.jobs.stereo import pair_done, stereo_frames
from generator.jobs.towns import town_runs
from generator.safeload import MAX_METADATA_BYTES, load_json
from generator.weather import TIMES, combinations

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
    """Whether ``lidar/sequences/NN`` is complete for this spec and plan (its metadata, read safely, says so)."""
    meta = out / "lidar" / "sequences" / plan.sequence / "lidar_meta.json"
    if not os.path.lexists(meta):
        return False
    n = 20 * len(plan.frames)  # the metadata grows with the scans (~2 KB and ~200 values each), ~15 sweeps a frame
    try:
        m = load_json(meta, max_bytes=MAX_METADATA_BYTES + n * 16 * 1024, max_nodes=100_000 + n * 2_000)
    except UserError:  # damaged: it is cast again
        return False
    if not isinstance(m, dict) or not isinstance(m.get("image_frames"), list):
        return False
    scene = m.get("scene")
    pairs = sorted(tuple(p) for p in m["image_frames"] if isinstance(p, list) and len(p) == 2)
    return (isinstance(scene, dict) and scene.get("spec_hash") == spec.spec_hash and scene.get("seed") == spec.seed
            and [k for k, _ in pairs] == sorted(plan.frames))


def images_done(out: Path, plan: Plan) -> list[int]:
    """Frames whose every planned image is complete on disk."""
    return [k for k in plan.frames if all(find_image(out, n, ".json").exists() for n in plan.images_of(k))]


def write_lidar(spec, cfg, out: Path, plan: Plan, scene=None, drive=None, first: int = 0) -> dict:
    """The whole drive's 10 Hz sweeps (:mod:`generator.jobs.drive`) into ``out/lidar/sequences/NN``
    (``spec``, ``plan``, ``first``: one town's, :class:`generator.jobs.towns.TownRun`)."""
    from generator.jobs.drive import plan_drive
    from generator.jobs.lidar_sequence import SequenceOptions, write_dataset_label_config, write_sequence
    from generator.layout.assemble import build_scene

    scene = build_scene(spec) if scene is None else scene
    drive = plan_drive(spec, scene, plan.frames, first) if drive is None else drive
    opts = SequenceOptions(frames=drive.sweeps, sequence=plan.sequence, resolution=cfg.resolution,
                           render_config=cfg.name, weather=True, image_frames=tuple(drive.image_frames))
    meta = write_sequence(scene, spec, out / "lidar", opts, world=drive.world)
    write_dataset_label_config(out / "lidar")
    return meta


@dataclasses.dataclass
class Preflight:
    """What :func:`preflight` found: the (merged) plan, the manifest to write, the towns, and the
    built scene and drive of each town (kept for a one-town run only; many towns are rebuilt
    one at a time, from the prototype cache, instead of all held in memory)."""

    plan: Plan
    manifest: dict
    towns: list
    built: dict

    def town(self, run):
        """(scene, drive) of ``run`` (a :class:`generator.jobs.towns.TownRun`), built again if not kept."""
        if run.index in self.built:
            return self.built[run.index]
        from generator.jobs.drive import plan_drive
        from generator.layout.assemble import build_scene

        scene = build_scene(run.spec)
        return scene, plan_drive(run.spec, scene, run.plan.frames, run.first)


def read_manifest(out: Path) -> dict | None:
    """The manifest of a folder being resumed, or None; a damaged one is a one-line error naming the field."""
    path = out / mf.NAME
    if not os.path.lexists(path):
        return None
    src = str(path)
    doc = load_json(path, source=src, max_bytes=MAX_METADATA_BYTES, max_nodes=8 * MAX_IMAGES + 100_000)

    def need(obj, key, kind, where=""):
        if not isinstance(obj, dict) or not isinstance(obj.get(key), kind):
            what = {str: "text", dict: "a mapping", list: "a list"}[kind]
            raise SpecError(src, where + key, f"must be {what} (not a manifest urbangen wrote; use another --out "
                                              "or delete the folder)")
        return obj[key]

    need(doc, "spec_hash", str)
    need(need(doc, "render_config", dict), "config_hash", str, "render_config.")
    plan = need(doc, "plan", dict)
    frames, combos = need(plan, "frames", list, "plan."), need(plan, "combos", list, "plan.")
    need(plan, "sequence", str, "plan.")
    if not all(type(k) is int and 0 <= k <= MAX_FRAME_INDEX for k in frames) or len(frames) > MAX_IMAGES:
        raise SpecError(src, "plan.frames", f"must be at most {MAX_IMAGES} frame numbers in 0..{MAX_FRAME_INDEX}")
    valid = {tuple(c) for c in combinations(TIMES)}
    if not all(isinstance(c, list) and tuple(c) in valid for c in combos):
        raise SpecError(src, "plan.combos", "must be [time_of_day, weather] pairs like [day, fog]")
    finished = need(doc, "finished", dict)
    if not isinstance(finished.get("images", []), list):
        raise SpecError(src, "finished.images", "must be a list of image names")
    if not isinstance(doc.get("runs", []), list):
        raise SpecError(src, "runs", "must be a list")
    return doc


def preflight(spec, cfg, opts: GenerateOptions) -> Preflight:
    """Check the whole run before anything is written (see the module docstring); a problem is one line."""
    from generator.labels import class_table
    from generator.layout.assemble import build_scene
    from generator.jobs.drive import plan_drive
    from generator.jobs.lidar_sequence import check_frames
    from generator.lidar.sensors import sensor_for_spec
    from generator.remission.models import intensity_fn_for_spec
    from generator.scan_effects.pipeline import processing_for_spec

    out, plan = Path(opts.out), opts.plan
    new = mf.new_manifest(spec, cfg, plan, opts.executor)
    old = read_manifest(out)
    manifest = new
    if old is not None:
        mf.check_compatible(old, new, out)
        manifest = mf.merge_plan(old, plan)
        plan = Plan.from_dict(manifest["plan"])
    check_plan(plan)
    towns = town_runs(spec, plan)
    sensor = sensor_for_spec(spec)  # every file the LiDAR stage reads, read now
    processing_for_spec(spec, sensor, True, intensity_fn_for_spec(spec))
    done = set(images_done(out, plan))
    todo = [k for k in plan.frames if k not in done]
    built, n_pairs, scans = {}, 0, 0
    for run in towns:  # the expensive checks last: each town, then its traffic
        scene = build_scene(run.spec)
        check_frames(scene, run.spec, max(run.local_frames) + 1)
        drive = plan_drive(run.spec, scene, run.plan.frames, run.first)
        seq_dir = out / "lidar" / "sequences" / run.plan.sequence
        n_pairs += sum(not pair_done(seq_dir, j) for j in stereo_frames(run.spec, range(drive.sweeps)))
        scans += 0 if lidar_done(out, run.plan, run.spec) else drive.sweeps
        if len(towns) == 1:
            built[run.index] = (scene, drive)
    per_image = image_bytes(cfg.width, cfg.height, cfg.exr_codec, len(class_table().names), cfg.preview)
    need = (len(todo) * len(plan.combos) + 2 * n_pairs) * per_image
    need += scans * scan_bytes(sensor.rays_per_sweep)
    check_free_space(out, need, f"{len(todo) * len(plan.combos)} images and {n_pairs} stereo pairs at "
                                f"{cfg.width}x{cfg.height}, {scans} scans" + (f" of {len(towns)} towns" if len(towns) > 1
                                                                             else ""))
    return Preflight(plan, manifest, towns, built)


def run_generate(spec, cfg, opts: GenerateOptions) -> dict:
    """Plan, render, scan and write a dataset into ``opts.out``; return the run record."""
    t0 = time.perf_counter()
    pre = preflight(spec, cfg, opts)
    out, plan, manifest = Path(opts.out), pre.plan, pre.manifest
    out.mkdir(parents=True, exist_ok=True)
    removed = clean_temporaries(out)
    shutil.rmtree(out / ".scratch", ignore_errors=True)
    if removed:
        log.info("removed %d unfinished temporary files of an interrupted run", removed)
    run = {"started": time.strftime("%Y-%m-%dT%H:%M:%S%z"), "executor": opts.executor, "workers": opts.workers}
    if len(pre.towns) > 1:
        run["towns"] = [{"town": r.index, "seed": r.spec.seed, "sequence": r.plan.sequence,
                         "frames": [min(r.plan.frames), max(r.plan.frames)]} for r in pre.towns]
    done = set(images_done(out, plan))
    manifest["finished"]["images"] = [n for k in plan.frames if k in done for n in plan.images_of(k)]
    manifest["finished"].setdefault("stereo", [])
    results, n_todo, n_stereo = [], 0, 0
    from generator.jobs.finish import write_openlabel, write_stats

    for town in pre.towns:
        tplan, tspec = town.plan, town.spec
        scene, drive = pre.town(town)
        if not lidar_done(out, tplan, tspec):
            t = time.perf_counter()
            write_lidar(tspec, cfg, out, tplan, scene, drive, town.first)
            run["lidar_s"] = round(run.get("lidar_s", 0.0) + time.perf_counter() - t, 2)
        manifest["finished"]["lidar"] = town is pre.towns[-1]
        mf.save(out, manifest)
        seq_dir = out / "lidar" / "sequences" / tplan.sequence
        todo = [k for k in tplan.frames if k not in done]
        pairs = stereo_frames(tspec, range(drive.sweeps))
        stereo_done = [k for k in pairs if pair_done(seq_dir, k)]
        stereo_todo = [k for k in pairs if k not in stereo_done]
        # a one-town run keeps its old record: the sweeps of its one sequence
        _set_stereo(manifest, tplan.sequence, stereo_done, len(pre.towns) > 1)
        if todo or stereo_todo:
            jobs = make_jobs(tspec, cfg, out, todo, plan.combos, opts.workers, stereo_todo, seq_dir, town.first)

            def on_frame(index, payload: dict, seq=tplan.sequence) -> None:
                manifest["finished"]["images"] += list(payload["images"])
                if "stereo" in payload:
                    _add_stereo(manifest, seq, payload["stereo"], len(pre.towns) > 1)
                mf.save(out, manifest)

            results.append(run_jobs(opts.executor, jobs, len(todo) + len(stereo_todo), on_frame, opts.ray_address))
            shutil.rmtree(out / ".scratch", ignore_errors=True)
            n_todo, n_stereo = n_todo + len(todo), n_stereo + len(stereo_todo)
        write_openlabel(tspec, out, tplan, scene, drive.world)  # the world the sequence was cast in
        mf.save(out, manifest)
        del scene, drive
    if results:
        run.update(_render_figures(results, n_todo, len(plan.combos)))
        run["stereo_pairs_rendered"] = n_stereo
    manifest["finished"]["openlabel"] = True
    write_stats(out)
    manifest["finished"]["stats"] = True
    run["wall_s"] = round(time.perf_counter() - t0, 2)
    manifest["runs"] = manifest.get("runs", []) + [run]
    mf.save(out, manifest)
    return run


def _set_stereo(manifest: dict, sequence: str, done: list[int], many: bool) -> None:
    """Record the finished stereo pairs of ``sequence`` (sweep numbers; ``"NN/j"`` when there are many towns)."""
    if not many:
        manifest["finished"]["stereo"] = list(done)
        return
    keep = [s for s in manifest["finished"]["stereo"] if not str(s).startswith(f"{sequence}/")]
    manifest["finished"]["stereo"] = keep + [f"{sequence}/{j}" for j in done]


def _add_stereo(manifest: dict, sequence: str, j: int, many: bool) -> None:
    manifest["finished"]["stereo"].append(f"{sequence}/{j}" if many else j)


def _render_figures(results, frames: int, per_frame: int) -> dict:
    """Throughput and where the workers' time went (over every town's pool run)."""
    workers = [w for res in results for w in res.done]
    wall = sum(res.wall_s for res in results)
    busy = sum(w["setup_s"] + w["frames_s"] for w in workers)
    cycles = sum(w["cycles_rgb_s"] for w in workers)
    rss = [(msg["frames_done"], msg["rss_mb"]) for res in results for msg in res.frame_seconds.values()]
    return {
        "render_wall_s": round(wall, 2),
        "frames_rendered": frames,
        "images_rendered": frames * per_frame,
        "frames_per_hour": round(3600.0 * frames / wall, 2) if wall else None,
        "images_per_hour": round(3600.0 * frames * per_frame / wall, 1) if wall else None,
        "worker_setup_s": [round(w["setup_s"], 2) for w in workers],
        "cycles_rgb_s": round(cycles, 2),
        "share_outside_rgb_sampling": round(1.0 - cycles / busy, 4) if busy else None,
        "worker_rss_mb": [round(w["rss_mb"], 1) for w in workers],
        "worker_max_rss_mb": [round(w["max_rss_mb"], 1) for w in workers],
        "rss_by_frames_done": sorted(rss),
    }
