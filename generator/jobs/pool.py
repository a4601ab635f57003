"""Run render workers in spawned processes and follow their progress.

Each worker is one process with one Blender and one scene build; frames are dealt
round-robin. The parent never imports bpy, so spawning is always safe.
"""

from __future__ import annotations

import dataclasses
import logging
import multiprocessing as mp
import os
import queue as queue_mod
import time
from dataclasses import dataclass, field
from pathlib import Path

from generator.progress import progress


log = logging.getLogger(__name__)


@dataclass
class PoolResult:
    """What the workers reported."""

    frame_seconds: dict[int, dict] = field(default_factory=dict)
    ready: list[dict] = field(default_factory=list)
    done: list[dict] = field(default_factory=list)
    wall_s: float = 0.0


def run_workers(target: str, jobs: list, total: int, desc: str = "render", on_frame=None) -> PoolResult:
    """Start one spawned process per job running ``target`` (``"module:function"``) and wait.

    Parameters
    ----------
    target : str
        Worker entry, called as ``function(job, queue)``.
    jobs : list of dataclass
        One job per worker (picklable, with a ``parent_pid`` field).
    total : int
        Number of ``("frame", ...)`` reports expected, for the progress bar.
    on_frame : callable, optional
        Called in the parent as ``on_frame(index, payload)`` for every finished frame.

    Raises
    ------
    RuntimeError
        With the worker's traceback when a worker fails.
    """
    module, func = target.split(":")
    ctx = mp.get_context("spawn")
    q = ctx.Queue()
    import importlib

    fn = getattr(importlib.import_module(module), func)
    jobs = [dataclasses.replace(job, parent_pid=os.getpid()) for job in jobs]
    procs = [ctx.Process(target=fn, args=(job, q), daemon=False) for job in jobs]
    t0 = time.perf_counter()
    for p in procs:
        p.start()

    def failed() -> str | None:
        dead = [p for p in procs if p.exitcode not in (None, 0)]
        return f"render worker {dead[0].pid} exited with code {dead[0].exitcode}" if dead else None

    ok = False
    try:
        res = follow(q.get, len(procs), total, desc, on_frame, failed)
        ok = True
    finally:
        for p in procs:  # finished workers are still flushing their queue: let them exit on their own
            p.join(timeout=60 if ok else 0)
            if p.is_alive():
                p.terminate()
                p.join(timeout=30)
        q.close()
        q.join_thread()
    res.wall_s = time.perf_counter() - t0
    return res


def follow(get, n_workers: int, total: int, desc: str, on_frame, failed) -> PoolResult:
    """Read worker messages with ``get(timeout=...)`` until every worker is done; drive the progress bar.

    ``failed()`` returns a message when a worker died without reporting (checked on timeouts).
    Shared by the local pool and the Ray executor.
    """
    res = PoolResult()
    with progress(total=total, desc=desc, unit="frame") as bar:
        while len(res.done) < n_workers:
            try:
                msg = get(timeout=1.0)
            except queue_mod.Empty:  # Ray's queue raises a subclass (wrapped in RayTaskError)
                problem = failed()
                if problem:
                    raise RuntimeError(problem)
                continue
            kind = msg[0]
            if kind == "frame":
                res.frame_seconds[msg[1]] = msg[2]
                if on_frame is not None:
                    on_frame(msg[1], msg[2])
                bar.update(1)
            elif kind == "ready":
                res.ready.append(msg[1])
            elif kind == "done":
                res.done.append(msg[1])
            elif kind == "error":
                raise RuntimeError("render worker failed:\n" + msg[1])
    return res


def deal(items: list, workers: int) -> list[list]:
    """Split ``items`` round-robin into ``workers`` non-empty lists."""
    workers = max(1, min(workers, len(items)))
    return [items[i::workers] for i in range(workers)]


def scratch_dir(out: Path, worker: int) -> Path:
    """Per-worker scratch folder inside the output folder (removed at the end of a run)."""
    return Path(out) / ".scratch" / f"worker{worker}"
