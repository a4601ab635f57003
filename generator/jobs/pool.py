"""The local executor: a pool of spawned worker processes on this machine.

Each of ``slots`` processes runs tasks one after another (:func:`serve`); a task that imported bpy
(``Task.fresh``) ends its process, which is replaced for the next task (one Blender per process:
its state cannot be reset). The parent never imports bpy, so spawning is always safe. Workers exit
when the parent dies (SIGKILL included).
"""

from __future__ import annotations

import logging
import multiprocessing as mp
import os
import queue as queue_mod
import traceback
from dataclasses import dataclass, field
from pathlib import Path

from generator.jobs.tasks import TaggedReport, Task, exit_with_parent, resolve

log = logging.getLogger(__name__)


@dataclass
class PoolResult:
    """What the workers of a ``render`` run reported (:func:`generator.jobs.executors.run_jobs`)."""

    frame_seconds: dict = field(default_factory=dict)
    ready: list[dict] = field(default_factory=list)
    done: list[dict] = field(default_factory=list)
    wall_s: float = 0.0


def serve(inbox, outbox, parent_pid: int) -> None:
    """A worker process: run the tasks ``inbox`` hands it until it hands ``None``."""
    exit_with_parent(parent_pid)
    while True:
        item = inbox.get()
        if item is None:
            return
        task_id, target, job, fresh = item
        try:
            resolve(target)(job, TaggedReport(outbox, task_id))
        except BaseException:  # report everything; the parent decides (a worker's own report came first)
            outbox.put((task_id, ("error", traceback.format_exc())))
            outbox.close()
            outbox.join_thread()
            os._exit(1)
        outbox.put((task_id, ("_end",)))
        if fresh:
            return


@dataclass
class _Worker:
    process: object
    inbox: object
    task: int | None = None
    retiring: bool = False


class LocalExecutor:
    """Up to ``slots`` tasks at once, each in a spawned process of this machine.

    Events (:meth:`events`): ``("msg", task_id, message)``, ``("ended", task_id)`` and
    ``("failed", task_id, reason)`` for a process that died without reporting.
    """

    name = "local"

    def __init__(self, slots: int):
        self.slots = max(1, int(slots))
        self.ctx = mp.get_context("spawn")
        self.outbox = self.ctx.Queue()
        self.workers: list[_Worker] = []

    # -- the executor protocol ---------------------------------------------------------------------------------------
    def has_slot(self) -> bool:
        return sum(w.task is not None for w in self.workers) < self.slots

    def submit(self, task: Task) -> None:
        w = next((w for w in self.workers if w.task is None and not w.retiring and w.process.is_alive()), None)
        if w is None:
            self._reap()
            inbox = self.ctx.Queue()
            proc = self.ctx.Process(target=serve, args=(inbox, self.outbox, os.getpid()), daemon=False)
            proc.start()
            w = _Worker(proc, inbox)
            self.workers.append(w)
        w.task = task.id
        w.retiring = task.fresh
        w.inbox.put((task.id, task.target, task.job, task.fresh))

    def events(self, timeout: float) -> list[tuple]:
        out, msgs = [], []
        try:
            msgs.append(self.outbox.get(timeout=timeout))
            while len(msgs) < 10_000:  # the rest next time
                msgs.append(self.outbox.get_nowait())
        except queue_mod.Empty:
            pass
        for task_id, msg in msgs:
            if msg[0] == "_end":
                w = next((w for w in self.workers if w.task == task_id), None)
                if w is not None:
                    w.task = None
                out.append(("ended", task_id))
            else:
                out.append(("msg", task_id, msg))
        if not out:
            for w in self.workers:
                code = w.process.exitcode
                if w.task is not None and code is not None:
                    out.append(("failed", w.task, f"worker process {w.process.pid} exited with code {code}"))
                    w.task = None
        return out

    def close(self, ok: bool = True) -> None:
        """Stop the workers: idle ones are asked to exit; the rest are terminated (a failed run)."""
        for w in self.workers:
            if w.process.is_alive() and w.task is None:
                w.inbox.put(None)
        for w in self.workers:  # finished workers are still flushing their queue: let them exit on their own
            w.process.join(timeout=60 if ok and w.task is None else 0)
            if w.process.is_alive():
                w.process.terminate()
                w.process.join(timeout=30)
        for w in self.workers:
            w.inbox.close()
        self.outbox.close()
        self.outbox.join_thread()
        self.workers = []

    def _reap(self) -> None:
        """Forget processes that have exited (retired after a fresh task)."""
        keep = []
        for w in self.workers:
            if w.task is None and not w.process.is_alive():
                w.process.join()
                w.inbox.close()
                continue
            keep.append(w)
        self.workers = keep


def deal(items: list, workers: int) -> list[list]:
    """Split ``items`` round-robin into ``workers`` non-empty lists."""
    workers = max(1, min(workers, len(items)))
    return [items[i::workers] for i in range(workers)]


def scratch_dir(out: Path, worker: int) -> Path:
    """Per-task scratch folder inside the output folder (removed at the end of a run)."""
    return Path(out) / ".scratch" / f"worker{worker}"
