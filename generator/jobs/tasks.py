"""Tasks: what the parent hands an executor, and how a task reports back.

A :class:`Task` names a function (``"module:function"``) and its job (a picklable dataclass). The
executor (:mod:`generator.jobs.pool` on this machine, :mod:`generator.jobs.ray_executor` on Ray)
calls ``function(job, report)`` in a worker process; the function reports on ``report`` with
``report.put(message)``:

* ``("ready", stats)`` -- set up (scene built, Blender ready ...);
* ``("frame", index, payload)`` -- an image frame or a stereo pair finished (its files are complete);
* ``("item", key, payload)`` -- another finished item (a town's LiDAR sequence, its OpenLABEL ...);
* ``("error", text)`` / ``("user_error", text)`` -- a bug (traceback) / a bad input (one line);
* ``("done", stats)`` -- the task's work is over.

The executor tags each message with the task's id, so the parent knows whose item it is, and
adds ``("_end",)`` when the function has returned. The parent (:mod:`generator.jobs.dispatch`)
records the items; the tasks write the dataset's files.
"""

from __future__ import annotations

import os
import threading
import time
from dataclasses import dataclass


@dataclass(frozen=True)
class Task:
    """One unit of work on an executor.

    Attributes
    ----------
    id : int
        Unique within a run (the parent's key for the task's messages).
    kind : str
        What it does (``scan``, ``render``, ``finish``, ``dataset``), for logs and figures.
    target : str
        ``"module:function"`` called as ``function(job, report)``.
    job : object
        Its picklable job.
    fresh : bool
        The worker process is not reused after this task (it imported bpy, whose state cannot be
        reset: one Blender per process).
    town : object
        The town the task belongs to (the parent's bookkeeping key; None for dataset tasks).
    cpus : int
        Cores the task asks of the executor (Ray's ``num_cpus``).
    attempt : int
        0, or how many earlier tasks lost this work (a node died under them).
    """

    id: int
    kind: str
    target: str
    job: object
    fresh: bool = False
    town: object = None
    cpus: int = 1
    attempt: int = 0


class TaggedReport:
    """``report.put(msg)`` for a task: puts ``(task_id, msg)`` on the executor's queue."""

    def __init__(self, queue, task_id: int):
        self.queue, self.task_id = queue, task_id

    def put(self, msg) -> None:
        self.queue.put((self.task_id, msg))


def resolve(target: str):
    """The function ``"module:function"`` names."""
    import importlib

    module, func = target.split(":")
    return getattr(importlib.import_module(module), func)


def exit_with_parent(parent: int, period_s: float = 0.5) -> None:
    """Exit at once when the parent process dies (a SIGKILLed parent cannot stop its workers).

    The parent's pid is passed in: comparing with the current parent pid also catches a parent
    that died before this thread started.
    """
    def watch() -> None:
        while True:
            if os.getppid() != parent:
                os._exit(1)
            time.sleep(period_s)

    threading.Thread(target=watch, name="parent-watchdog", daemon=True).start()
