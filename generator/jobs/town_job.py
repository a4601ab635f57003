"""Everything per town is a task: its scene, its LiDAR sequence, and after its images its boxes and exports.

A town's products are made by tasks on the executor, like its render jobs, so N workers (or N Ray
nodes) work on N towns at once and the parent only plans, dispatches and records. Each product is
one entry of :data:`TOWN_PRODUCTS`:

* stage ``scan``: needs the town only (its scene and its drive); runs first. ``lidar`` reports the
  drive's sweep count, which the parent needs to deal the town's stereo pairs to its render jobs.
* stage ``finish``: runs after the town's images and stereo pairs are complete (it may read them).

**Adding a per-town product** (a box file, an export): write ``def make(ctx: TownContext) -> dict``
that writes its files into ``ctx.out`` atomically (:mod:`generator.atomic`) and returns the words
to journal with it (``{}`` is fine), and add ``TownProduct("name", "scan" | "finish", make)`` to
:data:`TOWN_PRODUCTS`. ``generate`` then makes it for every town, records it in the journal
(``town NN name FRAMES``), counts it in ``manifest.json`` (``finished.towns.name``) and makes it
again on a resume only if the town's frames changed. ``ctx.scene`` and ``ctx.drive`` are built on
first use and shared by the task's products.
"""

from __future__ import annotations

import functools
import logging
import os
import resource
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from generator.errors import UserError
from generator.jobs.plan import Plan

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class TownJob:
    """One stage of one town's products (picklable).

    Attributes
    ----------
    spec : generator.spec.SceneSpec
        The town's spec (:func:`generator.spec.towns.town_spec`).
    config : generator.spec.render.RenderConfig
    out : str
        Dataset folder.
    plan : Plan
        The town's image frames, the run's variants, the town's sequence ``NN``.
    first : int
        Frame number at the start of the town's drive.
    products : tuple of str
        Names in :data:`TOWN_PRODUCTS` to make, in order.
    threads : int or None
        Threads for the LiDAR cast (None: every core).
    town_file : str
        Where the town's scene and drive are kept during the run (:mod:`generator.jobs.town_cache`): read
        from there when an earlier process built them, written there when this task builds them.
    """

    spec: object
    config: object
    out: str
    plan: Plan
    first: int
    products: tuple[str, ...]
    threads: int | None = None
    town_file: str = ""


def build_town(spec, frames, first: int) -> tuple:
    """(scene, drive) of the town of ``spec`` whose drive starts at frame ``first`` and covers image
    ``frames`` (a :class:`~generator.jobs.frameset.FrameSet`); raises when its route is too short for them."""
    from generator.jobs.drive import plan_drive
    from generator.jobs.lidar_sequence import check_frames
    from generator.layout import build_scene

    scene = build_scene(spec)
    check_frames(scene, spec, frames.max() - first + 1)  # the route fits the frames
    return scene, plan_drive(spec, scene, frames, first)


class TownContext:
    """What a town task's products share: the job, and the scene and drive, read or built once on first use."""

    def __init__(self, job: TownJob):
        self.job, self.spec, self.cfg, self.plan, self.first = job, job.spec, job.config, job.plan, job.first
        self.out = Path(job.out)

    @functools.cached_property
    def _town(self) -> tuple:
        """(scene, drive): kept by an earlier process of the run, else built here (and kept for the next)."""
        from generator.jobs import town_cache

        kept = town_cache.load(self.job.town_file, self.spec, self.plan.frames, self.first)
        if kept is not None:
            return kept
        scene, drive = build_town(self.spec, self.plan.frames, self.first)
        if self.job.town_file:
            town_cache.save(self.job.town_file, self.spec, self.plan.frames, self.first, scene, drive)
        return scene, drive

    @property
    def scene(self):
        return self._town[0]

    @property
    def drive(self):
        return self._town[1]


def write_lidar(spec, cfg, out: Path, plan: Plan, scene=None, drive=None, first: int = 0,
                threads: int | None = None) -> dict:
    """The whole drive's 10 Hz sweeps (:mod:`generator.jobs.drive`) into ``out/lidar/sequences/NN``
    (``spec``, ``plan``, ``first``: one town's). The dataset's label config, which sums every
    sequence, is written once at the end of the run (:func:`generator.jobs.finish.run_dataset`)."""
    from generator.jobs.drive import plan_drive
    from generator.jobs.lidar_sequence import SequenceOptions, write_sequence
    from generator.layout import build_scene

    scene = build_scene(spec) if scene is None else scene
    drive = plan_drive(spec, scene, plan.frames, first) if drive is None else drive
    opts = SequenceOptions(frames=drive.sweeps, sequence=plan.sequence, resolution=cfg.resolution,
                           render_config=cfg.name, weather=True, image_frames=tuple(drive.image_frames),
                           threads=threads, dataset_label_config=False)
    return write_sequence(scene, spec, Path(out) / "lidar", opts, world=drive.world, progress=False)


def _lidar(ctx: TownContext) -> dict:
    from generator.atomic import clean_temporaries

    seq = ctx.out / "lidar" / "sequences" / ctx.plan.sequence
    if seq.is_dir():
        clean_temporaries(seq)  # of a task that died writing it
    write_lidar(ctx.spec, ctx.cfg, ctx.out, ctx.plan, ctx.scene, ctx.drive, ctx.first, ctx.job.threads)
    return {"sweeps": ctx.drive.sweeps}


def _motion(ctx: TownContext) -> dict:
    from generator.dataset import Dataset
    from generator.jobs.motion import write_motion

    seq = ctx.plan.sequence
    figures = write_motion(Dataset(ctx.out, seq), ctx.drive.world, ctx.plan.frames, seq, ctx.cfg.exr_codec)
    return {"streams": len(figures)}


def _openlabel(ctx: TownContext) -> dict:
    from generator.jobs.finish import write_openlabel

    # the world the sequence was cast in; the box file reads the images' label supersampling
    write_openlabel(ctx.spec, ctx.out, ctx.plan, ctx.scene, ctx.drive.world, ctx.cfg.label_supersample)
    return {}


@dataclass(frozen=True)
class TownProduct:
    """One per-town product: its name (journal, manifest), its stage and what makes it."""

    name: str
    stage: str
    make: Callable[[TownContext], dict]


#: Every per-town product of ``generate``, in the order they are made (see the module docstring).
TOWN_PRODUCTS: tuple[TownProduct, ...] = (
    TownProduct("lidar", "scan", _lidar),
    TownProduct("motion", "finish", _motion),  # flow and disparity from the images' and stereo pairs' passes
    TownProduct("openlabel", "finish", _openlabel),  # OpenLABEL and the box file (visibility from the passes)
)
STAGES = ("scan", "finish")


def products(stage: str) -> tuple[str, ...]:
    return tuple(p.name for p in TOWN_PRODUCTS if p.stage == stage)


def run(job: TownJob, report) -> None:
    """Make ``job.products`` of one town and report each (``("item", ("town", NN, name), payload)``)."""
    t0, cpu0 = time.perf_counter(), time.process_time()
    table = {p.name: p for p in TOWN_PRODUCTS}
    ctx = TownContext(job)
    report.put(("ready", {"pid": os.getpid(), "town": job.spec.town_index, "sequence": job.plan.sequence}))
    seconds = {}
    try:
        for name in job.products:
            t = time.perf_counter()
            extra = table[name].make(ctx) or {}
            seconds[name] = time.perf_counter() - t
            report.put(("item", ("town", job.plan.sequence, name), {"extra": extra, "seconds": seconds[name]}))
    except UserError as e:
        report.put(("user_error", str(e)))
        return
    report.put(("done", {"pid": os.getpid(), "seconds": seconds, "wall_s": time.perf_counter() - t0,
                         "cpu_s": time.process_time() - cpu0, "start": t0,
                         "max_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
