"""Executors: where the render jobs of a plan run.

* ``local`` (default): one spawned process per worker on this machine
  (:func:`generator.jobs.pool.run_workers`).
* ``ray``: the same jobs as Ray tasks, on a local Ray instance or a cluster
  (``--ray-address``); the output folder must be on storage every node can write.

Both run :func:`generator.jobs.worker.run` per :class:`RenderJob` (one Blender and one scene build
per job, many frames) and report through a queue, so the parent's progress bar,
manifest updates and error handling are the same.
"""

from __future__ import annotations

import dataclasses
import logging
import os
import time
from dataclasses import dataclass
from pathlib import Path

from generator.errors import UserError
from generator.jobs.pool import PoolResult, deal, follow, run_workers, scratch_dir

log = logging.getLogger(__name__)
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
        Dataset folder; images go to ``out/images``.
    frames : tuple of int
        Frame indices this worker renders.
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
        Set by the local pool: the worker exits when its parent dies.
    first : int
        Frame number at the start of the town's drive (``spec`` is that town's spec;
        :mod:`generator.jobs.towns`); 0 for the one town.
    """

    spec: object
    config: object
    out: str
    frames: tuple[int, ...]
    combos: tuple[tuple[str, str], ...]
    scratch: str
    stereo: tuple[int, ...] = ()
    sequence_dir: str = ""
    parent_pid: int = 0
    first: int = 0


def make_jobs(spec, cfg, out: Path, frames: list[int], combos, workers: int, stereo: list[int] = (),
              sequence_dir: Path | None = None, first: int = 0) -> list[RenderJob]:
    """Deal the frames to render (``frames``: image variants, ``stereo``: stereo pairs) round-robin
    to ``workers`` jobs (fewer when there is less work).

    With a render config that asks for all cores (``threads: 0``) and several local
    workers, each job gets its share of the machine's cores.
    """
    frames, stereo = set(frames), set(stereo)
    parts = deal(sorted(frames | stereo), workers)
    if cfg.threads == 0 and len(parts) > 1:
        cfg = dataclasses.replace(cfg, threads=max(1, (os.cpu_count() or 1) // len(parts)))
    return [RenderJob(spec, cfg, str(out), tuple(k for k in part if k in frames), tuple(tuple(c) for c in combos),
                      str(scratch_dir(out, i)), tuple(k for k in part if k in stereo), str(sequence_dir or ""),
                      first=first)
            for i, part in enumerate(parts)]


def run_jobs(executor: str, jobs: list[RenderJob], total: int, on_frame=None, ray_address: str | None = None) -> PoolResult:
    """Run render ``jobs`` on ``executor``; see :func:`generator.jobs.pool.run_workers`."""
    if executor == "local":
        return run_workers(WORKER, jobs, total, "render", on_frame)
    if executor == "ray":
        return _run_ray(jobs, total, on_frame, ray_address)
    raise UserError(f"--executor: must be one of {', '.join(EXECUTORS)}, got {executor!r}")


def _ray_worker(job: RenderJob, queue) -> None:
    from generator.jobs.worker import run

    run(job, queue)


def _run_ray(jobs: list[RenderJob], total: int, on_frame, address: str | None) -> PoolResult:
    try:
        import ray
        from ray.util.queue import Queue
    except ImportError:
        raise UserError("--executor ray needs Ray: pip install 'urbangen[ray]' (or pip install 'ray>=2.9,<3')") from None
    started_here = not ray.is_initialized()
    if started_here:
        kwargs = {"address": address} if address else {"num_cpus": max(len(jobs), 1)}
        ray.init(include_dashboard=False, log_to_driver=False, logging_level=logging.WARNING, **kwargs)
    t0 = time.perf_counter()
    try:
        q = Queue()
        task = ray.remote(num_cpus=1, max_retries=0)(_ray_worker)
        refs = [task.remote(job, q) for job in jobs]

        def failed() -> str | None:
            ready, _ = ray.wait(refs, num_returns=len(refs), timeout=0)
            for r in ready:
                try:
                    ray.get(r)
                except Exception as e:  # noqa: BLE001 - report the remote failure
                    return f"ray render task failed: {e}"
            return None

        res = follow(q.get, len(jobs), total, "render (ray)", on_frame, failed)
        ray.get(refs)
    finally:
        if started_here:
            ray.shutdown()
    res.wall_s = time.perf_counter() - t0
    return res
