"""The parent's loop: hand tasks to an executor as they become runnable, pass what they report on.

The parent plans, dispatches and records; the tasks do the work. A :class:`TaskSource` says which
tasks may run now (:meth:`TaskSource.ready`: new ones appear as earlier ones report, e.g. a town's
renders once its drive is known), takes every message (:meth:`TaskSource.on_message`), learns
which tasks ended and replaces a lost task by one for its unfinished items
(:meth:`TaskSource.on_lost`; Ray only: a node that died). :func:`run_tasks` drives an executor
(:mod:`generator.jobs.pool`, :mod:`generator.jobs.ray_executor`) with it and draws the progress.
"""

from __future__ import annotations

import logging
import time
from collections import deque
from typing import Protocol

from generator.errors import UserError
from generator.jobs.tasks import Task
from generator.progress import progress

log = logging.getLogger(__name__)

#: How often one task's work may be lost (its node died) and handed to a new task before the run stops.
MAX_ATTEMPTS = 4


class TaskSource(Protocol):
    def ready(self) -> list[Task]: ...
    def on_message(self, task: Task, msg: tuple) -> None: ...
    def on_end(self, task: Task) -> None: ...
    def on_lost(self, task: Task, reason: str) -> list[Task]: ...
    def finished(self) -> bool: ...
    def total(self) -> int: ...
    def tick(self) -> None: ...


def run_tasks(executor, source: TaskSource, desc: str = "generate", unit: str = "item") -> dict:
    """Run every task ``source`` gives on ``executor`` until it is finished; returns figures.

    Raises
    ------
    UserError
        A task reported a bad input (``user_error``).
    RuntimeError
        A task failed (its traceback), a worker died without a word, or a task's work was lost
        more than :data:`MAX_ATTEMPTS` times.
    """
    t0 = time.perf_counter()
    tasks: dict[int, Task] = {}
    running: set[int] = set()
    waiting: deque[Task] = deque()
    lost = 0
    ok = False
    try:
        with progress(total=source.total(), desc=desc, unit=unit) as bar:
            while True:
                waiting.extend(source.ready())
                while waiting and executor.has_slot():
                    task = waiting.popleft()
                    tasks[task.id] = task
                    running.add(task.id)
                    executor.submit(task)
                if not running and not waiting:
                    if source.finished():
                        break
                    raise RuntimeError("nothing left to run but the plan is not finished (a bug in the task plan)")
                for event in executor.events(timeout=0.5):
                    kind, task = event[0], tasks[event[1]]
                    if kind == "msg":
                        msg = event[2]
                        if msg[0] == "error":
                            raise RuntimeError(f"{task.kind} task failed:\n{msg[1]}")
                        if msg[0] == "user_error":
                            raise UserError(msg[1])
                        source.on_message(task, msg)
                        if msg[0] in ("frame", "item"):
                            bar.update(1)
                    elif kind == "ended":
                        running.discard(task.id)
                        source.on_end(task)
                    elif kind == "lost":
                        running.discard(task.id)
                        lost += 1
                        again = source.on_lost(task, event[2])
                        if any(t.attempt >= MAX_ATTEMPTS for t in again):
                            raise RuntimeError(f"{task.kind} task lost {MAX_ATTEMPTS} times ({event[2]})")
                        log.warning("%s task %d lost (%s): its unfinished items go to %d new task(s)",
                                    task.kind, task.id, event[2], len(again))
                        waiting.extendleft(reversed(again))
                    elif kind == "failed":
                        raise RuntimeError(f"{task.kind} task {task.id} failed: {event[2]}")
                if bar.total != source.total():
                    bar.total = source.total()
                    if hasattr(bar, "refresh"):
                        bar.refresh()
                source.tick()
        ok = True
    finally:
        executor.close(ok)
    return {"wall_s": time.perf_counter() - t0, "tasks": len(tasks), "tasks_lost": lost,
            "nodes": sorted({str(n) for n in getattr(executor, "nodes", {}).values()})}


class FixedSource:
    """A fixed list of tasks, all runnable at once (a lost one runs again whole); keeps every message.

    For running a few tasks outside a ``generate`` plan (benches, tests): ``messages[task_id]`` holds what
    each task reported.
    """

    def __init__(self, tasks: list[Task]):
        self.todo = list(tasks)
        self.messages: dict[int, list] = {t.id: [] for t in tasks}
        self.n = len(tasks)
        self._next = max((t.id for t in tasks), default=0) + 1

    def ready(self) -> list[Task]:
        out, self.todo = self.todo, []
        return out

    def on_message(self, task: Task, msg: tuple) -> None:
        self.messages.setdefault(task.id, []).append(msg)

    def on_end(self, task: Task) -> None:
        pass

    def on_lost(self, task: Task, reason: str) -> list[Task]:
        again = Task(self._next, task.kind, task.target, task.job, task.fresh, task.town, task.cpus, task.attempt + 1)
        self._next += 1
        return [again]

    def finished(self) -> bool:
        return not self.todo

    def total(self) -> int:
        return self.n

    def tick(self) -> None:
        pass
