"""Executors: where the tasks of a plan run, and the render job.

* ``local`` (default): a pool of spawned processes on this machine (:mod:`generator.jobs.pool`).
* ``ray``: the same tasks as Ray tasks, on a local Ray instance or a cluster (``--ray-address``;
  :mod:`generator.jobs.ray_executor`); the output folder must be on storage every node can write.

Both run the same task functions (a render job: :func:`generator.jobs.worker.run`, one Blender and
one scene build per job, many frames) and report through a queue, so the parent's progress bar,
bookkeeping and error handling are the same (:mod:`generator.jobs.dispatch`).
"""

from __future__ import annotations

import dataclasses
import itertools
import os
from dataclasses import dataclass
from pathlib import Path

from generator.errors import UserError
from generator.jobs.frameset import FrameSet, count_frames, iter_frames
from generator.jobs.pool import PoolResult, scratch_dir
from generator.jobs.tasks import Task

WORKER = "generator.jobs.worker:run"
EXECUTORS = ("local", "ray")


@dataclass(frozen=True)
class RenderJob:
    """What one render worker does: one scene build, one Blender, many frames (picklable).

    Attributes
    ----------
    spec : generator.spec.SceneSpec
    config : generator.spec.render.RenderConfig
    out : str
        Dataset folder; images go to ``out/images/SSSS`` (:mod:`generator.imaging.paths`).
    frames : tuple of int or range
        Frame indices this worker renders (a ``range`` stands for its frames: a million-frame job
        is a few ranges; :func:`generator.jobs.frameset.iter_frames`).
    combos : tuple of (str, str)
        (time_of_day, weather) variants of every frame.
    scratch : str
        The worker's own scratch folder (Blender's temporary EXRs, ``blender.log``).
    stereo : tuple of int
        Scans whose KITTI stereo pair this worker renders into ``sequence_dir``
        (:mod:`generator.jobs.stereo`).
    sequence_dir : str
        The LiDAR sequence folder the stereo pairs belong to.
    parent_pid : int
        When set, the worker exits when that process dies (the local pool watches its parent itself).
    first : int
        Frame number at the start of the town's drive (``spec`` is that town's spec;
        :mod:`generator.jobs.towns`); 0 for the one town.
    town : tuple
        ``(town file, the town's image frames)``: where the town's scene and drive may be kept
        (:mod:`generator.jobs.town_cache`); ``()``: build them.
    """

    spec: object
    config: object
    out: str
    frames: tuple
    combos: tuple[tuple[str, str], ...]
    scratch: str
    stereo: tuple[int, ...] = ()
    sequence_dir: str = ""
    parent_pid: int = 0
    first: int = 0
    town: tuple = ()

    @property
    def n_items(self) -> int:
        return count_frames(self.frames) + len(self.stereo)


def render_threads(cfg, parts: int, executor: str = "local"):
    """The render config of one of ``parts`` local render jobs: with ``threads: 0`` (all cores) and several
    jobs, each gets its share of the machine's cores."""
    if executor == "local" and cfg.threads == 0 and parts > 1:
        return dataclasses.replace(cfg, threads=max(1, (os.cpu_count() or 1) // parts))
    return cfg


def deal_render(spec, cfg, out: Path, frames: FrameSet, combos, workers: int, stereo=(),
                sequence_dir: Path | None = None, first: int = 0, scratch_ids=None,
                executor: str = "local", town: tuple = ()) -> list[RenderJob]:
    """Deal ``frames`` (image variants) and ``stereo`` (stereo pairs) round-robin to ``workers`` jobs (fewer
    when there is less work); the frames stay ranges. ``town``: :attr:`RenderJob.town` of every job."""
    stereo = sorted(set(stereo))
    parts = max(1, min(workers, len(frames) + len(stereo)))
    frame_parts = frames.deal(parts) if frames else []
    frame_parts += [()] * (parts - len(frame_parts))
    # the stereo pairs go first to the parts with fewer frames
    order = sorted(range(parts), key=lambda i: (count_frames(frame_parts[i]), i))
    stereo_parts = [[] for _ in range(parts)]
    for n, j in enumerate(stereo):
        stereo_parts[order[n % parts]].append(j)
    cfg = render_threads(cfg, parts, executor)
    ids = scratch_ids if scratch_ids is not None else itertools.count()
    jobs = []
    for fp, sp in zip(frame_parts, stereo_parts, strict=True):
        if fp or sp:
            jobs.append(RenderJob(spec, cfg, str(out), tuple(fp), tuple(tuple(c) for c in combos),
                                  str(scratch_dir(out, next(ids))), tuple(sp), str(sequence_dir or ""), first=first,
                                  town=town))
    return jobs


def make_jobs(spec, cfg, out: Path, frames, combos, workers: int, stereo=(), sequence_dir: Path | None = None,
              first: int = 0) -> list[RenderJob]:
    """Render jobs of ``frames`` (any iterable of frame numbers) and ``stereo`` pairs (``render``)."""
    return deal_render(spec, cfg, out, FrameSet.of(frames), combos, workers, stereo, sequence_dir, first)


def make_executor(executor: str, slots: int, ray_address: str | None = None):
    """The executor named ``executor`` with ``slots`` tasks at once."""
    if executor == "local":
        from generator.jobs.pool import LocalExecutor

        return LocalExecutor(slots)
    if executor == "ray":
        from generator.jobs.ray_executor import RayExecutor

        return RayExecutor(slots, ray_address)
    raise UserError(f"--executor: must be one of {', '.join(EXECUTORS)}, got {executor!r}")


class _JobsSource:
    """A fixed list of render jobs (``render``): every one runnable at once; a lost one is re-dealt."""

    def __init__(self, jobs: list[RenderJob], target: str, on_frame):
        self.ids = itertools.count()
        self.todo = [Task(next(self.ids), "render", target, job, fresh=True) for job in jobs]
        self.on_frame, self.target = on_frame, target
        self.result = PoolResult()
        self.done_frames: set = set()
        self.n = sum(job.n_items for job in jobs)

    def ready(self):
        out, self.todo = self.todo, []
        return out

    def on_message(self, task, msg) -> None:
        kind = msg[0]
        if kind == "frame" and msg[1] not in self.done_frames:
            self.done_frames.add(msg[1])
            self.result.frame_seconds[msg[1]] = msg[2]
            if self.on_frame is not None:
                self.on_frame(msg[1], msg[2])
        elif kind == "ready":
            self.result.ready.append(msg[1])
        elif kind == "done":
            self.result.done.append(msg[1])

    def on_end(self, task) -> None:
        pass

    def on_lost(self, task, reason):
        job = task.job
        frames = tuple(k for k in iter_frames(job.frames) if k not in self.done_frames)
        stereo = tuple(j for j in job.stereo if ("stereo", j) not in self.done_frames)
        if not frames and not stereo:
            return []
        again = dataclasses.replace(job, frames=frames, stereo=stereo)
        return [dataclasses.replace(task, id=next(self.ids), job=again, attempt=task.attempt + 1)]

    def finished(self) -> bool:
        return True

    def total(self) -> int:
        return self.n

    def tick(self) -> None:
        pass


def run_jobs(executor: str, jobs: list[RenderJob], total: int, on_frame=None, ray_address: str | None = None,
             target: str = WORKER) -> PoolResult:
    """Run render ``jobs`` on ``executor`` (one task each, all at once); ``on_frame(index, payload)`` per
    finished frame."""
    from generator.jobs.dispatch import run_tasks

    source = _JobsSource(jobs, target, on_frame)
    figures = run_tasks(make_executor(executor, max(1, len(jobs)), ray_address), source, desc=f"render ({executor})",
                        unit="frame")
    source.result.wall_s = figures["wall_s"]
    return source.result
