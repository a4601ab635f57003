"""The Ray executor: the same tasks as Ray tasks, on a local Ray instance or a cluster (``--ray-address``).

The output folder must be on storage every node can write (and read: a task reads what another
wrote, e.g. a town's finishing task reads its LiDAR sequence). Messages come back through one Ray
queue whose actor is pinned to the parent's node, so losing any other node loses no message.

A node that dies takes its running tasks with it: Ray reports them lost (``WorkerCrashedError``,
``NodeDiedError`` ...) and :meth:`RayExecutor.events` says so (``("lost", task_id, reason)``); the
parent then hands the task's unfinished items to a new task (:mod:`generator.jobs.dispatch`), so
nothing is lost and, since the parent records each item once, nothing is counted twice. Ray's own
retries are off (``max_retries=0``): a retried task would redo the items it had finished.
A task that failed in its own code (``RayTaskError``) fails the run, as on the local executor.
"""

from __future__ import annotations

import logging
import queue as queue_mod

from generator.errors import UserError
from generator.jobs.tasks import TaggedReport, Task, resolve

log = logging.getLogger(__name__)

RAY_HINT = "--executor ray needs Ray: pip install 'urbangen[ray]' (or pip install 'ray>=2.9,<3')"


def _run_task(target: str, job, queue, task_id: int) -> dict:
    """The body of every Ray task: the function, then the end marker (after its last message)."""
    import ray

    report = TaggedReport(queue, task_id)
    report.put(("node", ray.get_runtime_context().get_node_id()))
    resolve(target)(job, report)
    report.put(("_end",))
    return {"task": task_id}


class RayExecutor:
    """Up to ``slots`` tasks at once on Ray.

    Parameters
    ----------
    slots : int
        Tasks in flight at once (``--workers``).
    address : str, optional
        A running cluster (``host:port``, ``ray://host:port`` or ``auto``); None starts a local Ray
        with ``slots`` CPUs (stopped again by :meth:`close`).
    """

    name = "ray"

    def __init__(self, slots: int, address: str | None = None):
        try:
            import ray
            from ray.util.queue import Queue
            from ray.util.scheduling_strategies import NodeAffinitySchedulingStrategy
        except ImportError:
            raise UserError(RAY_HINT) from None
        self.ray = ray
        self.slots = max(1, int(slots))
        self.started_here = not ray.is_initialized()
        if self.started_here:
            kwargs = {"address": address} if address else {"num_cpus": self.slots}
            ray.init(include_dashboard=False, log_to_driver=False, logging_level=logging.WARNING, **kwargs)
        here = ray.get_runtime_context().get_node_id()
        self.queue = Queue(actor_options={"num_cpus": 0,
                                          "scheduling_strategy": NodeAffinitySchedulingStrategy(here, soft=False)})
        self._reused = ray.remote(max_retries=0)(_run_task)
        self._fresh = ray.remote(max_retries=0, max_calls=1)(_run_task)  # a process that imported bpy ends
        self.refs: dict = {}       # object ref -> task id, for tasks not yet ended
        self.nodes: dict = {}      # task id -> node id it runs on

    def has_slot(self) -> bool:
        return len(self.refs) < self.slots

    def submit(self, task: Task) -> None:
        fn = self._fresh if task.fresh else self._reused
        ref = fn.options(num_cpus=task.cpus).remote(task.target, task.job, self.queue, task.id)
        self.refs[ref] = task.id

    def events(self, timeout: float) -> list[tuple]:
        out, msgs = [], []
        try:
            msgs.append(self.queue.get(timeout=timeout))
            n = self.queue.qsize()
            if n:
                msgs += self.queue.get_nowait_batch(min(n, 10_000))
        except queue_mod.Empty:
            pass
        ended = set()
        for task_id, msg in msgs:
            if msg[0] == "_end":
                ended.add(task_id)
                out.append(("ended", task_id))
            elif msg[0] == "node":
                self.nodes[task_id] = msg[1]
            else:
                out.append(("msg", task_id, msg))
        for ref, task_id in list(self.refs.items()):
            if task_id in ended:
                del self.refs[ref]
        out += self._finished_badly()
        return out

    def _finished_badly(self) -> list[tuple]:
        """Tasks whose ref is ready with an error: ``failed`` (their own code) or ``lost`` (node, worker process)."""
        ray = self.ray
        if not self.refs:
            return []
        ready, _ = ray.wait(list(self.refs), num_returns=len(self.refs), timeout=0, fetch_local=False)
        out = []
        for ref in ready:
            try:
                ray.get(ref, timeout=0)
                continue  # done; its end marker is on the way
            except ray.exceptions.RayTaskError as e:
                out.append(("failed", self.refs.pop(ref), f"ray task failed: {e}"))
            except ray.exceptions.GetTimeoutError:
                continue
            except ray.exceptions.RayError as e:
                out.append(("lost", self.refs.pop(ref), f"{type(e).__name__}: {str(e).splitlines()[0][:200]}"))
        return out

    def close(self, ok: bool = True) -> None:
        ray = self.ray
        if not ok:
            for ref in list(self.refs):
                try:
                    ray.cancel(ref, force=True)
                except Exception:  # noqa: BLE001 - best effort on the way out
                    pass
        try:
            self.queue.shutdown()
        except Exception:  # noqa: BLE001
            pass
        if self.started_here:
            ray.shutdown()
