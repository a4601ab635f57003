"""Executors: where the render jobs of a plan run.

* ``local`` (default): one spawned process per worker on this machine
  (:func:`generator.jobs.pool.run_workers`).
* ``ray``: the same jobs as Ray tasks, on a local Ray instance or a cluster
  (``--ray-address``); the output folder must be on storage every node can write.

Both run :func:`generator.blender.worker.run` per job (one Blender and one scene build
per job, many frames) and report through a queue, so the parent's progress bar,
manifest updates and error handling are the same.
"""

from __future__ import annotations

import logging
import time

from generator.errors import UserError
from generator.jobs.pool import PoolResult, follow, run_workers

log = logging.getLogger(__name__)
WORKER = "generator.blender.worker:run"
EXECUTORS = ("local", "ray")


def run_jobs(executor: str, jobs: list[dict], total: int, on_frame=None, ray_address: str | None = None) -> PoolResult:
    """Run render ``jobs`` on ``executor``; see :func:`generator.jobs.pool.run_workers`."""
    if executor == "local":
        return run_workers(WORKER, jobs, total, "render", on_frame)
    if executor == "ray":
        return _run_ray(jobs, total, on_frame, ray_address)
    raise UserError(f"--executor: must be one of {', '.join(EXECUTORS)}, got {executor!r}")


def _ray_worker(job: dict, queue) -> None:
    from generator.blender.worker import run

    run(job, queue)


def _run_ray(jobs: list[dict], total: int, on_frame, address: str | None) -> PoolResult:
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
