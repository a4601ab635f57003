"""Entry point of a render worker process (spawned locally, or a Ray task).

The parent (pure Python, no bpy) starts workers with the ``spawn`` start method and
hands each one a :class:`generator.jobs.executors.RenderJob`. The worker builds the
SceneModel, the world in time and the Blender renderer once
(:class:`generator.blender.renderer.Renderer`, the only bpy it touches), asks the rig for each
frame, exposes it at the frame's time on the drive's timeline (actors where their tracks are,
motion blur when the render config asks), renders its variants, writes
each image's files atomically and reports progress on a queue:
``("ready", stats)``, ``("frame", index, {"images": {name: seconds}, "rss_mb": ...})``,
``("error", message)`` and ``("done", stats)`` (including the seconds spent inside
Cycles' render calls, to measure the share of wall time outside sampling).
Blender's own per-tile chatter on stdout is sent to ``blender.log`` in the scratch folder.
"""

from __future__ import annotations

import contextlib
import logging
import os
import resource
import time
import traceback
from pathlib import Path

from generator.jobs.frameset import iter_frames, last_frame
from generator.jobs.tasks import exit_with_parent

log = logging.getLogger(__name__)


@contextlib.contextmanager
def _stdout_to(path: Path):
    """Redirect the process's C-level stdout (Blender prints render progress there)."""
    fd = os.open(str(path), os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o644)
    saved = os.dup(1)
    try:
        os.dup2(fd, 1)
        yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)
        os.close(fd)


def run(job, queue) -> None:
    """Render ``job.frames`` (a :class:`~generator.jobs.executors.RenderJob`) and report on ``queue``."""
    if job.parent_pid:
        exit_with_parent(job.parent_pid)
    try:
        scratch = Path(job.scratch)
        scratch.mkdir(parents=True, exist_ok=True)
        with _stdout_to(scratch / "blender.log"):
            _run(job, queue, scratch)
    except BaseException as e:  # report everything; the parent decides
        queue.put(("error", f"{type(e).__name__}: {e}\n{traceback.format_exc()}"))
        raise SystemExit(1) from e


def _run(job, queue, scratch: Path) -> None:
    from generator.blender.renderer import Renderer  # imports bpy (after the sys.path clean-up)
    from generator.jobs.towns import local_frame
    from generator.jobs.variants import render_frames
    from generator.layout import build_scene
    from generator.world.rig import Rig

    spec, cfg = job.spec, job.config  # a re-drawn town's own spec: build_scene makes that town
    t = time.perf_counter()
    kept = _kept_town(job)
    if kept is not None:  # the town's drive covers every frame and sweep of the town: this job's too
        scene, world = kept[0], kept[1].world
    else:
        scene = build_scene(spec)
        world = _world(spec, scene, job)
    rig = Rig.from_world(spec, world)
    layout_s = time.perf_counter() - t
    renderer = Renderer(scene, spec, cfg, scratch, world)
    queue.put(("ready", {"layout_s": layout_s, "blender_build_s": renderer.build_seconds, "pid": os.getpid()}))

    t_start = time.perf_counter()
    indices = list(iter_frames(job.frames))
    frames = [local_frame(rig, index, job.first) for index in indices]
    for n, (index, (_, images)) in enumerate(zip(indices, render_frames(renderer, spec, cfg, frames, Path(job.out),
                                                                         job.combos, rig), strict=True), 1):
        queue.put(("frame", index, {"images": images, "rss_mb": _rss_mb(), "frames_done": n}))
    if job.stereo:
        from generator.jobs.stereo import render_pair
        from generator.lidar.sensors import sensor_for_spec

        sensor = sensor_for_spec(spec)
        for n, index in enumerate(job.stereo, len(indices) + 1):
            secs = render_pair(renderer, spec, cfg, rig, sensor, index, Path(job.sequence_dir))
            queue.put(("frame", ("stereo", index), {"images": {}, "stereo": index, "seconds": secs,
                                                    "rss_mb": _rss_mb(), "frames_done": n}))
    cycles = renderer.cycles_seconds
    queue.put(("done", {
        "pid": os.getpid(), "frames": len(indices) + len(job.stereo),
        "max_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
        "rss_mb": _rss_mb(), "setup_s": layout_s + renderer.build_seconds, "frames_s": time.perf_counter() - t_start,
        "cycles_rgb_s": cycles["rgb"], "cycles_labels_s": cycles["labels"],
    }))


def _kept_town(job):
    """The town's (scene, drive) as an earlier process of the run kept them (:mod:`generator.jobs.town_cache`),
    or None."""
    if not job.town:
        return None
    from generator.jobs import town_cache

    path, frames = job.town
    return town_cache.load(path, job.spec, frames, job.first)


def _world(spec, scene, job):
    """The world in time over this job's frames and stereo sweeps.

    The same world the parent planned (:func:`generator.jobs.drive.plan_drive` over all frames):
    the traffic simulation is causal and seeded by name, so a shorter run has the same state at
    every instant it covers; it only has to reach this job's last frame and last stereo sweep.
    """
    from generator.jobs.drive import MARGIN_M
    from generator.traffic.build import build_world
    from generator.world.rig import SWEEP_PERIOD_S

    last = last_frame(job.frames, job.first) - job.first
    duration = (max(job.stereo) + 1) * SWEEP_PERIOD_S + 0.2 if job.stereo else 0.0
    return build_world(spec, scene, duration, last * spec.paths.spacing_m + MARGIN_M)


def _rss_mb() -> float:
    """Resident set size of this process now, MiB (Linux /proc; 0 elsewhere)."""
    try:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20
    except OSError:
        return 0.0
