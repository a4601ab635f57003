"""``urbangen generate``: the whole dataset of a spec, resumable, at any scale.

The parent plans, dispatches and records; tasks on the executor (local processes or Ray nodes) do
the work (:mod:`generator.jobs.schedule`): per town a scan task (scene, drive, LiDAR sequence:
:mod:`generator.jobs.town_job`), its render tasks (images in every weather x time combination and
the KITTI stereo pairs, :mod:`generator.jobs.stereo`), a finishing task (OpenLABEL ...); then one
dataset task (label config, statistics). One town unless ``town.redraw_every_frames`` is set, then
town ``i`` (its own seed, its own drive from t = 0) makes sequence ``NN + i``
(:mod:`generator.jobs.towns`).

Bookkeeping: every finished item is one line appended to the journal (:mod:`generator.jobs.journal`),
O(1) per item; ``manifest.json`` (:mod:`generator.jobs.manifest`) is the summary, written at the
start, every few seconds' checkpoint and the end. A rerun reads the journal, not the files, and does
what is left; everything is written atomically, so a run killed at any moment resumes to exactly the
files of an uninterrupted run.

Before the first write, :func:`preflight` checks the whole run: the manifest of a folder being
resumed (readable, same spec, config and sequence, the merged plan), the plan against what the
file names allow (:func:`generator.jobs.plan.check_plan`, sequence numbers in
:class:`generator.jobs.towns.TownPlan`), the scene, sensor and intensity files the LiDAR reads, the
route's room for the frames of the first town with work left (the other towns' routes are checked
by their own tasks), and the disk the run will write against the free space at the output. A bad
input therefore leaves no folder behind; ``--plan-only`` stops there.
"""

from __future__ import annotations

import dataclasses
import logging
import shutil
import time
from pathlib import Path

from generator.atomic import TMP_PREFIX, clean_temporaries
from generator.imaging.paths import image_dir
from generator.jobs import manifest as mf
from generator.jobs.journal import Journal, Ledger
from generator.jobs.plan import Plan, check_free_space, check_plan, human, image_bytes, motion_bytes, scan_bytes
from generator.jobs.resume import read_journal, read_manifest
from generator.jobs.stereo import stereo_frames
from generator.jobs.towns import TownPlan

log = logging.getLogger(__name__)


@dataclasses.dataclass
class GenerateOptions:
    """Options of one ``generate`` run (validated by the command).

    ``stand_in``: every task is a stand-in (:mod:`generator.jobs.dry`; benches and tests of the
    bookkeeping; no scene is built, no disk estimate made). ``plan_only``: check and summarise the
    plan, write nothing.
    """

    out: Path
    plan: Plan
    workers: int = 1
    executor: str = "local"
    ray_address: str | None = None
    split: str | None = None
    plan_only: bool = False
    stand_in: bool = False
    stand_in_delay_s: float = 0.0


@dataclasses.dataclass
class Preflight:
    """What :func:`preflight` found: the (merged) plan, the manifest to write, the towns, what is done
    (the journal, read), and the disk the run will write."""

    plan: Plan
    manifest: dict
    towns: TownPlan
    journal: Journal
    need_bytes: int
    what: str
    fresh: bool
    built: dict = dataclasses.field(default_factory=dict)  # town index -> (scene, drive) of the canary


def _estimate(spec, cfg, out: Path, plan: Plan, towns: TownPlan, ledger: Ledger, stand_in: bool,
              built: dict | None = None) -> tuple[int, str]:
    """Bytes the run will write and what they hold. The first town with work left is built (its route
    checked against its frames, its drive planned; kept in ``built[index]`` as ``(scene, drive)`` for the
    town's tasks); other towns' scans and stereo pairs are estimated from its sweeps per frame."""
    from generator.jobs.journal import combo_mask
    from generator.labels import class_table
    from generator.lidar.sensors import sensor_for_spec

    mask = combo_mask(plan.combos)
    left = ledger.frames_left(plan.frames, mask)
    images = len(left) * len(plan.combos)
    if stand_in:
        return 0, f"{images} stand-in images"
    sensor = sensor_for_spec(spec)
    canary, scans, pairs = None, 0, 0  # canary: (sweeps, frames) of the one town built
    for index in towns.indices:
        seq, frames = towns.sequence(index), towns.frames(index)
        lidar = ledger.town_done(seq, "lidar", frames)
        if lidar is not None:
            sweeps = int(lidar.get("sweeps", 0))
        elif canary is None:
            scene, drive = _canary(towns.run(index))
            canary = drive.sweeps, len(frames)
            sweeps = canary[0]
            if built is not None:
                built[index] = scene, drive
        else:
            sweeps = -(-canary[0] * len(frames) // canary[1])
        scans += 0 if lidar is not None else sweeps
        done = ledger.stereo.get(seq, ())
        pairs += sum(j not in done for j in stereo_frames(spec, range(sweeps)))
    per_image = image_bytes(cfg.width, cfg.height, cfg.exr_codec, len(class_table().names), cfg.preview)
    need = (images + 2 * pairs) * per_image + scans * scan_bytes(sensor.rays_per_sweep)
    need += (len(left) + 3 * pairs) * motion_bytes(cfg.width, cfg.height)  # flows (a frame; both cameras) + disparity
    what = (f"{images} images and {pairs} stereo pairs at {cfg.width}x{cfg.height}, {scans} scans"
            + (f" of {len(towns)} towns" if len(towns) > 1 else ""))
    return need, what


def _canary(run) -> tuple:
    """Build one town: its route must fit its frames; its scene and drive."""
    from generator.jobs.town_job import build_town

    return build_town(run.spec, run.plan.frames, run.first)


def preflight(spec, cfg, opts: GenerateOptions) -> Preflight:
    """Check the whole run before anything is written (see the module docstring); a problem is one line."""
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
    towns = TownPlan(spec, plan)
    if not opts.stand_in:
        sensor = sensor_for_spec(spec)  # every file the LiDAR stage reads, read now
        processing_for_spec(spec, sensor, True, intensity_fn_for_spec(spec))
    journal = read_journal(out, old, plan, towns)
    built = {}
    need, what = _estimate(spec, cfg, out, plan, towns, journal.ledger, opts.stand_in, built)
    if not opts.stand_in:
        check_free_space(out, need, what)
    return Preflight(plan, manifest, towns, journal, need, what, old is None, built)


def _clean(out: Path, pre: Preflight, sequences: list[str]) -> None:
    """Temporaries of an interrupted run, only where unfinished items are (``sequences``: of the towns with
    work left; never a walk over a million finished files)."""
    from generator.jobs.journal import combo_mask

    shutil.rmtree(out / ".scratch", ignore_errors=True)
    removed = sum(p.unlink() is None for p in out.glob(TMP_PREFIX + "*") if p.is_file())
    for sub in ("openlabel", "boxes", "flow", "stats", "stand-in"):
        if (out / sub).is_dir():
            removed += sum(p.unlink() is None for p in (out / sub).glob(TMP_PREFIX + "*"))
    left = pre.journal.ledger.frames_left(pre.plan.frames, combo_mask(pre.plan.combos))
    for a, b in left.ranges:
        for shard in range(a // 100, (b - 1) // 100 + 1):
            folder = image_dir(out, shard * 100)
            if folder.is_dir():
                removed += sum(p.unlink() is None for p in folder.glob(TMP_PREFIX + "*"))
    for seq in sequences:
        folder = out / "lidar" / "sequences" / seq
        if folder.is_dir() and not folder.is_symlink():
            removed += clean_temporaries(folder)
    if removed:
        log.info("removed %d unfinished temporary files of an interrupted run", removed)


def run_generate(spec, cfg, opts: GenerateOptions) -> dict:
    """Plan, dispatch and record a dataset into ``opts.out``; return the run record (``--plan-only``: the plan)."""
    from generator.jobs.dispatch import run_tasks
    from generator.jobs.executors import make_executor
    from generator.jobs.schedule import RunSetup, RunSource

    t0 = time.perf_counter()
    pre = preflight(spec, cfg, opts)
    out, plan, manifest = Path(opts.out), pre.plan, pre.manifest
    if opts.plan_only:
        return {"plan_only": True, "frames": len(plan.frames), "images": plan.n_images, "towns": len(pre.towns),
                "sequences": [pre.towns.sequence(pre.towns.indices[0]), pre.towns.sequence(pre.towns.indices[-1])],
                "disk": human(pre.need_bytes), "writes": pre.what}
    out.mkdir(parents=True, exist_ok=True)
    journal = pre.journal
    if pre.fresh and journal.exists():
        journal.remove()  # left by a folder whose manifest is gone: not this dataset's
    run = {"started": time.strftime("%Y-%m-%dT%H:%M:%S%z"), "executor": opts.executor, "workers": opts.workers}
    if len(pre.towns) > 1:
        run["towns"] = {"count": len(pre.towns), "sequences": [pre.towns.sequence(pre.towns.indices[0]),
                                                                pre.towns.sequence(pre.towns.indices[-1])]}
    setup = RunSetup(spec, cfg, out, plan, pre.towns, journal, opts.workers, opts.executor, opts.split,
                     opts.stand_in, opts.stand_in_delay_s)

    def checkpoint(source) -> None:
        manifest["finished"] = _summary(source)
        mf.save(out, manifest)

    source = RunSource(setup, checkpoint)
    _clean(out, pre, [pre.towns.sequence(i) for i in source.pending])
    _keep_built(out, pre)
    journal.settle()  # a dataset from before the journal gets one now
    checkpoint(source)
    try:
        figures = run_tasks(make_executor(opts.executor, opts.workers, opts.ray_address), source, desc="generate")
    finally:
        journal.close()
        shutil.rmtree(out / ".scratch", ignore_errors=True)
    for folder in sorted(source.dirty):  # where tasks lost on a dead node were writing
        if folder.is_dir():
            clean_temporaries(folder)
    journal.compact()
    run.update(_figures(source, figures, len(plan.combos)))
    run["wall_s"] = round(time.perf_counter() - t0, 2)
    manifest["finished"] = _summary(source)
    manifest["runs"] = manifest.get("runs", []) + [run]
    mf.save(out, manifest)
    return run


def _keep_built(out: Path, pre: Preflight) -> None:
    """Hand the town the preflight built to the town's tasks (:mod:`generator.jobs.town_cache`), then let it go."""
    from generator.jobs import town_cache

    for index, (scene, drive) in pre.built.items():
        run = pre.towns.run(index)
        town_cache.save(town_cache.town_file(out, pre.towns.sequence(index)), run.spec, run.plan.frames, run.first,
                        scene, drive)
    pre.built.clear()


def _summary(source) -> dict:
    s = source.s
    return mf.finished_summary(s.plan, source.ledger, len(s.towns), dict(source.done_products),
                               source.ledger.dataset.get("stats") == source.fingerprint)


def _figures(source, figures: dict, per_frame: int) -> dict:
    """Throughput, where the workers' time went and what the parent did (bookkeeping)."""
    f = source.figures
    render = [d for d in f["done"] if d["kind"] == "render"]
    wall = figures["wall_s"]
    busy = sum(d.get("setup_s", 0.0) + d.get("frames_s", 0.0) for d in render)
    cycles = sum(d.get("cycles_rgb_s", 0.0) for d in render)
    out = {"tasks": figures["tasks"], "tasks_lost": figures["tasks_lost"], "dispatch_wall_s": round(wall, 2),
           "town_products_s": {k: round(v, 2) for k, v in f["products"].items()},
           "stereo_pairs_rendered": f["stereo"]}
    if figures["nodes"]:
        out["ray_nodes"] = figures["nodes"]
    if f["frames"]:
        out.update({
            "render_wall_s": round(wall, 2),
            "frames_rendered": f["frames"],
            "images_rendered": f["images"],
            "frames_per_hour": round(3600.0 * f["frames"] / wall, 2) if wall else None,
            "images_per_hour": round(3600.0 * f["images"] / wall, 1) if wall else None,
            "worker_setup_s": [round(d.get("setup_s", 0.0), 2) for d in render],
            "cycles_rgb_s": round(cycles, 2),
            "share_outside_rgb_sampling": round(1.0 - cycles / busy, 4) if busy else None,
            "worker_rss_mb": [round(d.get("rss_mb", 0.0), 1) for d in render],
            "worker_max_rss_mb": [round(d.get("max_rss_mb", 0.0), 1) for d in render],
            "rss_by_frames_done": sorted(f["rss"]),
        })
    return out
