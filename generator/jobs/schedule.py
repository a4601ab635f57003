"""The tasks of a ``generate`` run, town by town, and the record of what they finish.

Per town (:mod:`generator.jobs.towns`), in this order:

1. a ``scan`` task: the town's scan-stage products (:mod:`generator.jobs.town_job`; its LiDAR
   sequence, which tells the sweep count and so the town's stereo pairs);
2. its ``render`` tasks: its unfinished image frames and stereo pairs, dealt to up to ``--workers``
   render jobs (:func:`generator.jobs.executors.deal_render`);
3. a ``finish`` task once they are all complete: the finish-stage products (OpenLABEL ...);

and when every town is done, one ``dataset`` task (label config, statistics). A town's tasks
become runnable as the previous step reports; several towns are in flight at once (up to twice
``--workers``), so N workers scan, render and finish N towns together. Nothing is held per town
before the town is started, so a plan of a million towns costs memory only for the towns in flight.

Every finished item is recorded once, as its message arrives (:class:`generator.jobs.journal.Journal`:
O(1) per item); an item reported twice (a lost task's work done again) is recorded once.
"""

from __future__ import annotations

import dataclasses
import hashlib
import itertools
import json
import logging
import os
import time
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path

from generator.imaging.paths import image_dir
from generator.jobs.executors import WORKER, deal_render
from generator.jobs.finish import DATASET_PRODUCTS, DatasetJob
from generator.jobs.frameset import FrameSet, iter_frames
from generator.jobs.journal import Journal, combo_mask
from generator.jobs.plan import Plan
from generator.jobs.stereo import stereo_frames
from generator.jobs.tasks import Task
from generator.jobs.town_cache import discard, town_file
from generator.jobs.town_job import STAGES, TownJob, products
from generator.jobs.towns import TownPlan

log = logging.getLogger(__name__)

#: Seconds between two rewrites of ``manifest.json``'s summary while items finish.
CHECKPOINT_S = 30.0
TARGETS = {"render": WORKER, "scan": "generator.jobs.town_job:run", "finish": "generator.jobs.town_job:run",
           "dataset": "generator.jobs.finish:run_dataset"}
STAND_IN_TARGETS = {"render": "generator.jobs.dry:render", "scan": "generator.jobs.dry:town",
                    "finish": "generator.jobs.dry:town", "dataset": "generator.jobs.dry:dataset"}


@dataclass
class RunSetup:
    """What the task plan needs to know of a run."""

    spec: object
    cfg: object
    out: Path
    plan: Plan
    towns: TownPlan
    journal: Journal
    workers: int
    executor: str = "local"
    split: str | None = None
    stand_in: bool = False
    stand_in_delay_s: float = 0.0


@dataclass
class _Town:
    index: int | None
    seq: str
    frames: FrameSet
    run: object
    todo: dict = field(default_factory=dict)   # stage -> products still to make
    sweeps: int | None = None
    renders_out: int = 0


def plan_fingerprint(plan: Plan, split: str | None) -> str:
    """What the dataset products were made for: the plan and the split (a change makes them again)."""
    doc = json.dumps({"plan": plan.to_dict(), "split": split}, sort_keys=True).encode()
    return hashlib.sha256(doc).hexdigest()[:16]


class RunSource:
    """The task source of a ``generate`` run (:class:`generator.jobs.dispatch.TaskSource`)."""

    def __init__(self, setup: RunSetup, checkpoint=None):
        self.s = setup
        self.journal, self.ledger = setup.journal, setup.journal.ledger
        self.mask = combo_mask(setup.plan.combos)
        self.fingerprint = plan_fingerprint(setup.plan, setup.split)
        self.checkpoint, self._last_checkpoint = checkpoint, time.monotonic()
        self.ids = itertools.count()
        self.scratch_ids = itertools.count()
        self.window = max(2, 2 * setup.workers)
        self.active: dict = {}
        self.new: list[Task] = []
        self.dataset_todo = tuple(p for p in DATASET_PRODUCTS if self.ledger.dataset.get(p) != self.fingerprint)
        self.dataset_issued = False
        self.towns_done = 0
        self.dirty: set[Path] = set()  # folders a lost task was writing in (their temporaries go at the end)
        self.figures = {"images": 0, "frames": 0, "stereo": 0, "ready": [], "done": [], "rss": [],
                        "products": {}, "cycles_rgb_s": 0.0}
        self.done_products = {p: 0 for stage in STAGES for p in products(stage)}
        self._pending = self._survey()
        if self._pending:  # any town work makes the dataset products again (they read every town's output)
            self.dataset_todo = DATASET_PRODUCTS
        self._total = self._count_total()

    # -- what is left --
    def _frames_left(self, frames: FrameSet) -> FrameSet:
        return self.ledger.frames_left(frames, self.mask)

    def _town_state(self, index) -> _Town:
        towns = self.s.towns
        t = _Town(index, towns.sequence(index), towns.frames(index), None)
        for stage in STAGES:
            t.todo[stage] = tuple(p for p in products(stage) if self.ledger.town_done(t.seq, p, t.frames) is None)
        lidar = self.ledger.town_done(t.seq, "lidar", t.frames)
        if lidar is not None and "sweeps" in lidar:
            t.sweeps = int(lidar["sweeps"])
        return t

    def _stereo_left(self, t: _Town) -> list[int]:
        if t.sweeps is None:
            return []
        done = self.ledger.stereo.get(t.seq, ())
        return [j for j in stereo_frames(self.s.spec, range(t.sweeps)) if j not in done]

    def _survey(self) -> deque:
        """The towns with anything left to do (one pass at the start; counts what is done)."""
        pending = deque()
        frames_left = self._frames_left(self.s.plan.frames)
        self.frames_left = len(frames_left)
        for index in self.s.towns.indices:
            t = self._town_state(index)
            for stage in STAGES:
                for p in products(stage):
                    self.done_products[p] += p not in t.todo[stage]
            lo, hi = t.frames.min(), t.frames.max() + 1
            if any(t.todo.values()) or frames_left.intersection(lo, hi) or self._stereo_left(t):
                pending.append(index)
        return pending

    def _count_total(self) -> int:
        """Items to record: frames, town products, dataset products (stereo pairs are added as their towns'
        drives become known)."""
        towns = len(self.s.towns)
        return self.frames_left + sum(towns - n for n in self.done_products.values()) + len(self.dataset_todo)

    # -- tasks --
    def _task(self, kind: str, job, town, attempt: int = 0) -> Task:
        target = (STAND_IN_TARGETS if self.s.stand_in else TARGETS)[kind]
        if self.s.stand_in:
            from generator.jobs.dry import StandIn

            job = StandIn(job, self.s.stand_in_delay_s)
        return Task(next(self.ids), kind, target, job, fresh=kind == "render" and not self.s.stand_in, town=town,
                    attempt=attempt)

    def _town_threads(self) -> int | None:
        """Threads of a scan or finish task: its share of the cores. A run of one town has nothing to run
        beside its scan and its finishing (they come before and after its renders), so they get every core."""
        if self.s.executor != "local" or self.s.workers <= 1:
            return None
        return max(1, (os.cpu_count() or 1) // min(self.s.workers, len(self.s.towns)))

    def _stage_task(self, t: _Town, stage: str, attempt: int = 0) -> Task:
        run = t.run
        job = TownJob(run.spec, self.s.cfg, str(self.s.out), run.plan, run.first, t.todo[stage], self._town_threads(),
                      self._town_file(t))
        return self._task(stage, job, t.index, attempt)

    def _town_file(self, t: _Town) -> str:
        """Where the town's tasks keep its scene and drive for each other (none for stand-ins)."""
        return "" if self.s.stand_in else str(town_file(self.s.out, t.seq))

    def _advance(self, t: _Town) -> None:
        """Issue the town's next tasks: scan, else its renders, else its finishing, else it is done."""
        if t.todo["scan"]:
            self.new.append(self._stage_task(t, "scan"))
            return
        frames = self._frames_left(t.frames)
        stereo = self._stereo_left(t)
        if (frames or stereo) and t.renders_out == 0:
            seq_dir = self.s.out / "lidar" / "sequences" / t.seq
            jobs = deal_render(t.run.spec, self.s.cfg, self.s.out, frames, self.s.plan.combos, self.s.workers, stereo,
                               seq_dir, t.run.first, self.scratch_ids, self.s.executor,
                               (self._town_file(t), t.run.plan.frames))
            t.renders_out = len(jobs)
            self._total += len(stereo)
            self.new += [self._task("render", job, t.index) for job in jobs]
            return
        if t.renders_out:
            return
        if t.todo["finish"]:
            self.new.append(self._stage_task(t, "finish"))
            return
        del self.active[t.index]
        discard(self._town_file(t))
        self.towns_done += 1

    def ready(self) -> list[Task]:
        while len(self.active) < self.window and self._pending:
            index = self._pending.popleft()
            t = self._town_state(index)
            t.run = self.s.towns.run(index)
            self.active[index] = t
            self._advance(t)
        if not self._pending and not self.active and self.dataset_todo and not self.dataset_issued:
            self.dataset_issued = True
            job = DatasetJob(str(self.s.out), self.dataset_todo, self.s.split,
                             tuple(self.s.towns.sequence(i) for i in self.s.towns.indices) if self.s.split else ())
            self.new.append(self._task("dataset", job, None))
        out, self.new = self.new, []
        return out

    # -- messages --
    def on_message(self, task: Task, msg: tuple) -> None:
        kind = msg[0]
        f = self.figures
        if kind == "frame":
            payload = msg[2]
            if "stereo" in payload:
                seq = self.s.towns.sequence(task.town)
                f["stereo"] += self.journal.record_stereo(seq, int(payload["stereo"]))
            else:
                names = list(payload["images"])
                combos = [tuple(n[7:].split("_", 1)) for n in names]
                if self.journal.record_frame(int(msg[1]), combos):
                    f["frames"] += 1
                    f["images"] += len(names)
                n = int(payload.get("frames_done", 0))
                if n and n & (n - 1) == 0:  # powers of two: a bounded sample of the workers' memory
                    f["rss"].append((n, payload.get("rss_mb", 0.0)))
        elif kind == "item":
            key, payload = msg[1], msg[2]
            if key[0] == "town":
                t = self.active.get(task.town)
                frames = t.frames if t is not None else self.s.towns.frames(task.town)
                extra = payload.get("extra", {})
                if self.journal.record_town(key[1], key[2], frames, **extra):
                    self.done_products[key[2]] = self.done_products.get(key[2], 0) + 1
                if t is not None:
                    for stage in STAGES:
                        t.todo[stage] = tuple(p for p in t.todo[stage] if p != key[2])
                    if key[2] == "lidar":
                        t.sweeps = int(extra["sweeps"])
                f["products"][key[2]] = f["products"].get(key[2], 0.0) + float(payload.get("seconds", 0.0))
            elif key[0] == "dataset":
                self.journal.record_dataset(key[1], self.fingerprint)
                self.dataset_todo = tuple(p for p in self.dataset_todo if p != key[1])
        elif kind in ("ready", "done"):
            f[kind].append({"kind": task.kind, **msg[1]})

    def on_end(self, task: Task) -> None:
        if task.kind == "dataset":
            if self.dataset_todo:
                raise RuntimeError(f"the dataset task ended without {', '.join(self.dataset_todo)}")
            return
        t = self.active[task.town]
        if task.kind in STAGES:
            left = [p for p in (task.job.job if self.s.stand_in else task.job).products if p in t.todo[task.kind]]
            if left:
                raise RuntimeError(f"the {task.kind} task of sequence {t.seq} ended without {', '.join(left)}")
        elif task.kind == "render":
            t.renders_out -= 1
            if t.renders_out == 0 and (self._frames_left(t.frames) or self._stereo_left(t)):
                raise RuntimeError(f"the render tasks of sequence {t.seq} ended with frames or pairs unfinished")
        self._advance(t)

    def on_lost(self, task: Task, reason: str) -> list[Task]:
        """A task whose node died: a new task for what it had not finished (none if it had finished all)."""
        job = task.job.job if self.s.stand_in else task.job
        if task.town is not None:
            self.dirty.add(self.s.out / "lidar" / "sequences" / self.s.towns.sequence(task.town))
        self.dirty.update({self.s.out / sub for sub in ("openlabel", "stats", "stand-in")})
        if task.kind == "render":
            self.dirty.update({image_dir(self.s.out, k) for k in iter_frames(job.frames)})
            frames = [k for k in iter_frames(job.frames) if not self.ledger.frame_done(k, self.mask)]
            done = self.ledger.stereo.get(self.s.towns.sequence(task.town), ())
            stereo = tuple(j for j in job.stereo if j not in done)
            if frames or stereo:
                again = dataclasses.replace(job, frames=tuple(FrameSet.of(frames).deal(1)[0]) if frames else (),
                                            stereo=stereo)
                return [self._task("render", again, task.town, task.attempt + 1)]
        elif task.kind in STAGES:
            t = self.active[task.town]
            left = tuple(p for p in job.products if p in t.todo[task.kind])
            if left:
                return [self._task(task.kind, dataclasses.replace(job, products=left), task.town, task.attempt + 1)]
        elif self.dataset_todo:
            return [self._task("dataset", dataclasses.replace(job, products=self.dataset_todo), None, task.attempt + 1)]
        self.on_end(task)
        return []

    @property
    def pending(self) -> list:
        """The towns not yet started that have work left (in order)."""
        return list(self._pending)

    def finished(self) -> bool:
        return not self._pending and not self.active and not self.dataset_todo

    def total(self) -> int:
        return self._total

    def tick(self) -> None:
        now = time.monotonic()
        if self.checkpoint is not None and now - self._last_checkpoint >= CHECKPOINT_S:
            self._last_checkpoint = now
            self.checkpoint(self)

