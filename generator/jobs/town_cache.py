"""A town built once per run: its scene and drive, handed from the process that built them to the others.

Every task of a town (its scan, its render jobs, its finishing) needs the town's scene
(:func:`generator.layout.build_scene`) and drive (:func:`generator.jobs.drive.plan_drive`); built
afresh they cost ~12 s of one core per task (a town of 3 x 3 blocks), while the pickled pair (~60 MB) is
written in ~0.15 s and read in ~0.15 s. So the first process that builds a town (``generate``'s
preflight for the first town, else the town's scan task) writes them to
``out/.scratch/towns/NN.pickle`` and the later tasks read them.

Both are pure functions of the spec, the town's frames and its first frame, which the file records;
a file that does not match what a task would build (or cannot be read) is ignored and the task
builds the town itself. Pickling keeps every array's bytes, so a read town makes the same dataset,
byte for byte, as one built in the task. The files live in the run's scratch folder, which ``generate``
removes at its start and end; a town's file goes when the town is done.
"""

from __future__ import annotations

import logging
import os
import pickle
import time
from pathlib import Path

from generator.jobs.frameset import FrameSet

log = logging.getLogger(__name__)

#: Bump when what the file holds changes shape.
VERSION = 1


def town_file(out, sequence: str) -> Path:
    """Where the built town of sequence ``sequence`` of dataset ``out`` is kept during a run."""
    return Path(out) / ".scratch" / "towns" / f"{sequence}.pickle"


def _header(spec, frames, first: int) -> dict:
    return {"version": VERSION, "spec": spec, "frames": FrameSet.of(frames).to_json(), "first": int(first)}


def save(path: str | os.PathLike, spec, frames, first: int, scene, drive) -> None:
    """Write ``scene`` and ``drive`` (built from ``spec``, image ``frames``, ``first``) to ``path`` atomically."""
    path = Path(path)
    t = time.perf_counter()
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    with open(tmp, "wb") as f:
        pickle.dump((_header(spec, frames, first), scene, drive), f, protocol=pickle.HIGHEST_PROTOCOL)
    os.replace(tmp, path)
    log.info("town kept in %s (%.2f s)", path, time.perf_counter() - t)


def load(path: str | os.PathLike | None, spec, frames, first: int):
    """``(scene, drive)`` kept in ``path`` for exactly this ``spec``, ``frames`` and ``first``, else None."""
    if not path or not Path(path).is_file():
        return None
    t = time.perf_counter()
    try:
        with open(path, "rb") as f:
            header, scene, drive = pickle.load(f)
    except Exception as e:  # a file of another version or a torn one: build the town instead
        log.warning("%s: not read (%s); building the town", path, e)
        return None
    if header != _header(spec, frames, first):
        log.warning("%s: kept for another town; building the town", path)
        return None
    log.info("town read from %s (%.2f s)", path, time.perf_counter() - t)
    return scene, drive


def discard(path: str | os.PathLike | None) -> None:
    """Remove a town's file (the town is done)."""
    if path:
        Path(path).unlink(missing_ok=True)
