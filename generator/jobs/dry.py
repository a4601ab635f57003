"""Stand-in tasks: the parent's planning, dispatch and bookkeeping without Blender or a LiDAR cast.

``generate`` with ``GenerateOptions(stand_in=True)`` runs every task through these functions instead
of the real ones: each writes a tiny (empty) stand-in file where the real task writes its item and
reports exactly what the real one reports. Benches measure the parent with them
(``bench/bookkeeping.py``) and tests kill runs and Ray nodes under them; their datasets are not
datasets (no pixels, no points).

A stand-in's items are deterministic: a town's drive has :func:`stand_in_sweeps` sweeps. ``delay_s``
(:class:`StandIn`) makes each item take that long, so a test can act mid-run.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass
from pathlib import Path

from generator.atomic import TMP_PREFIX
from generator.imaging.paths import image_name, image_path  # not from jobs.images: EXR, schema, PIL (~0.5 s a worker)
from generator.jobs.frameset import iter_frames

STAND_IN_DIR = "stand-in"


@dataclass(frozen=True)
class StandIn:
    """A real job (a ``RenderJob``, ``TownJob`` or ``DatasetJob``) done by a stand-in; ``delay_s`` per item."""

    job: object
    delay_s: float = 0.0


def stand_in_sweeps(frames) -> int:
    """The stand-in drive of a town: two sweeps per image frame and one more."""
    return 2 * len(frames) + 1


def touch(path: Path) -> None:
    """An empty file at ``path``, appearing whole (a temporary renamed in), its folder made if needed."""
    tmp = path.parent / f"{TMP_PREFIX}{path.name}.{os.getpid()}"
    try:
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
    except FileNotFoundError:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
    os.close(fd)
    os.replace(tmp, path)


def render(stand: StandIn, report) -> None:
    """A render job: an empty ``.json`` per image variant (the metadata, written last by the real one)
    and an empty ``image_3`` PNG per stereo pair."""
    job, out = stand.job, Path(stand.job.out)
    report.put(("ready", {"layout_s": 0.0, "blender_build_s": 0.0, "pid": os.getpid()}))
    t0 = time.perf_counter()
    n = 0
    for k in iter_frames(job.frames):
        n += 1
        time.sleep(stand.delay_s)
        names = [image_name(k, t, w) for t, w in job.combos]
        for name in names:
            touch(image_path(out, name, ".json"))
        report.put(("frame", k, {"images": dict.fromkeys(names, {}), "rss_mb": 0.0, "frames_done": n}))
    for j in job.stereo:
        n += 1
        time.sleep(stand.delay_s)
        touch(Path(job.sequence_dir) / "image_3" / f"{j:06d}.png")
        report.put(("frame", ("stereo", j), {"images": {}, "stereo": j, "seconds": {}, "rss_mb": 0.0,
                                             "frames_done": n}))
    report.put(("done", {"pid": os.getpid(), "frames": n, "max_rss_mb": 0.0, "rss_mb": 0.0, "setup_s": 0.0,
                         "frames_s": time.perf_counter() - t0, "cycles_rgb_s": 0.0, "cycles_labels_s": 0.0}))


def town(stand: StandIn, report) -> None:
    """A town's products: an empty ``stand-in/NN.<product>`` each; ``lidar`` reports the stand-in sweeps."""
    job = stand.job
    report.put(("ready", {"pid": os.getpid(), "town": job.spec.town_index, "sequence": job.plan.sequence}))
    for name in job.products:
        time.sleep(stand.delay_s)
        touch(Path(job.out) / STAND_IN_DIR / f"{job.plan.sequence}.{name}")
        extra = {"sweeps": stand_in_sweeps(job.plan.frames)} if name == "lidar" else {}
        report.put(("item", ("town", job.plan.sequence, name), {"extra": extra, "seconds": 0.0}))
    report.put(("done", {"pid": os.getpid(), "seconds": {}, "wall_s": 0.0, "max_rss_mb": 0.0}))


def dataset(stand: StandIn, report) -> None:
    """The dataset products: an empty ``stand-in/dataset.<product>`` each."""
    job = stand.job
    report.put(("ready", {"pid": os.getpid()}))
    for name in job.products:
        touch(Path(job.out) / STAND_IN_DIR / f"dataset.{name}")
        report.put(("item", ("dataset", name), {"seconds": 0.0}))
    report.put(("done", {"pid": os.getpid()}))
