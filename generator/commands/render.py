"""``urbangen render SPEC --config CFG --out DIR [--frames N] [--variants V] [--workers N] [--executor local|ray]``.

Renders frames along the scene's route: per image one multilayer EXR (RGB + one mask
channel per class + depth + instance), a metadata JSON and a preview PNG, in
``DIR/images/``. ``--variants all`` renders the 6 weathers at every time of day the spec lists
(``weather.times_of_day``; default day and night: 12 combinations, 6 RGB renders; fog and rain
in post). Images whose metadata already
exists are skipped (rerun = resume).

A spec with ``town.redraw_every_frames = N`` is rendered as ``generate`` renders it: frame ``k``
shows town ``k // N`` (its own seed, driven from its own start; :mod:`generator.spec.towns`), so
the images are those of a ``generate`` run of the same spec and frames.
"""

from __future__ import annotations

import logging
import re
import shutil
from dataclasses import dataclass
from pathlib import Path

from generator.atomic import TMP_PREFIX
from generator.commands.options import Integer, path, shown, text_path
from generator.commands.preflight import os_reason, output_dir
from generator.errors import UserError
from generator.imaging.paths import find_image, has_images, image_dir, image_path, images_root
from generator.jobs.executors import EXECUTORS, make_jobs, run_jobs
from generator.jobs.plan import (
    MAX_FRAME_INDEX,
    MAX_FRAMES,
    MAX_WORKERS,
    check_free_space,
    check_plan,
    check_workers,
    image_bytes,
    make_plan,
)
from generator.jobs.variants import parse_combos
from generator.spec import load_spec
from generator.spec.render import load_render_config

log = logging.getLogger(__name__)


def add_render_arguments(p, out_help: str, frames: int, variants: str) -> None:
    """The options ``render`` and ``generate`` share (with their own defaults)."""
    p.add_argument("spec", type=text_path, help="scene spec JSON (e.g. scenes/default_town.json)")
    p.add_argument("--config", required=True, type=text_path,
                   help="render config YAML or preset name (test, preview, paper)")
    p.add_argument("--out", required=True, type=path, help=out_help)
    p.add_argument("--frames", type=Integer(1, MAX_FRAMES), default=frames,
                   help=f"frames along the route, 1..{MAX_FRAMES} (default {frames})")
    p.add_argument("--variants", default=variants,
                   help=f"all (6 weathers x the spec's times of day per frame, 12 by default), clear (day, "
                        f"clear), or pairs like day:fog,dusk:clear,night:rain (default {variants})")
    p.add_argument("--workers", type=Integer(1, MAX_WORKERS), default=1,
                   help="parallel Blender processes (default 1; local: at most one per core)")
    p.add_argument("--executor", default="local", choices=EXECUTORS,
                   help="where the render workers run: local (spawned processes, default) or ray")
    p.add_argument(
        "--ray-address", default=None, help="address of an existing Ray cluster (default: start a local one)"
    )


def register(sub) -> None:
    p = sub.add_parser("render", help="render RGB + label EXRs with metadata along the route",
                       description=__doc__.split("\n\n")[1])
    add_render_arguments(p, "output folder", frames=2, variants="clear")
    p.add_argument("--first", type=Integer(0, MAX_FRAME_INDEX), default=0,
                   help="index of the first frame (default 0)")
    p.set_defaults(func=run)


@dataclass(frozen=True)
class RenderArgs:
    """The validated options ``render`` and ``generate`` share."""

    spec: object
    cfg: object
    out: Path
    combos: list


def check_render_args(args) -> RenderArgs:
    """Load the spec and config and check the shared options; a bad one is a one-line user error."""
    spec = load_spec(args.spec)
    cfg = load_render_config(args.config)
    out = output_dir(args.out, "--out")
    try:
        combos = parse_combos(args.variants, spec.weather.times_of_day)
    except ValueError as e:
        raise UserError(f"--variants: {e}") from None
    check_workers(args.workers, args.executor)
    if args.executor == "ray":
        check_ray(args.ray_address)
    elif args.ray_address is not None:
        raise UserError("--ray-address: only with --executor ray")
    return RenderArgs(spec, cfg, out, combos)


def check_ray(address: str | None, timeout_s: float = 3.0) -> None:
    """Ray is installed and the cluster at ``address`` (``host:port`` or ``ray://host:port``) answers.

    ``ray.init`` on an address nobody listens at waits for minutes; this is found in seconds,
    before anything is written. ``auto`` (Ray's own lookup) is left to Ray.
    """
    import importlib.util
    import socket

    if importlib.util.find_spec("ray") is None:
        raise UserError("--executor ray needs Ray: pip install 'urbangen[ray]' (or pip install 'ray>=2.9,<3')")
    if address is None or address == "auto":
        return
    m = re.fullmatch(r"(?:ray://)?(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9_.-]{1,253}):([0-9]{1,5})", address)
    if not m or not 1 <= int(m.group(2)) <= 65535:
        raise UserError(f"--ray-address: expected host:port or ray://host:port (or auto), got {shown(address)}")
    host, port = m.group(1).strip("[]"), int(m.group(2))
    try:
        socket.create_connection((host, port), timeout=timeout_s).close()
    except OSError as e:
        reason = "no answer" if isinstance(e, TimeoutError) else os_reason(e)
        raise UserError(f"--ray-address: cannot reach {host}:{port} ({reason})") from None


def run(args) -> int:
    from generator.labels import class_table

    r = check_render_args(args)
    out, combos, cfg = r.out, r.combos, r.cfg
    plan = make_plan(args.frames, args.first, combos)
    check_plan(plan)
    todo = [k for k in plan.frames if not all(find_image(out, n, ".json").exists() for n in plan.images_of(k))]
    if not todo:
        log.info("all %d frames already rendered in %s", args.frames, out)
        return 0
    n_images = len(todo) * len(combos)
    per_image = image_bytes(cfg.width, cfg.height, cfg.exr_codec, len(class_table().names), cfg.preview)
    check_free_space(out, n_images * per_image, f"{n_images} images at {cfg.width}x{cfg.height}")
    created = not out.exists()
    try:
        done, wall = {}, 0.0
        for tspec, first, frames in towns_of(r.spec, todo):  # one town unless the spec re-draws towns
            jobs = make_jobs(tspec, cfg, out, frames, combos, args.workers, first=first)
            res = run_jobs(args.executor, jobs, len(frames), None, args.ray_address)
            done.update(res.frame_seconds)
            wall += res.wall_s
    except BaseException:
        _remove_unfinished(out, plan, created)
        raise
    finally:
        shutil.rmtree(out / ".scratch", ignore_errors=True)
    n = sum(len(msg["images"]) for msg in done.values())
    print(f"rendered {n} images of {len(done)} frames into {images_root(out)} in {wall:.1f} s")
    return 0


def towns_of(spec, frames: list[int]) -> list[tuple[object, int, list[int]]]:
    """(town spec, frame number of the start of its drive, its frames) per town the ``frames`` show:
    the spec itself with every frame when it re-draws no town, else town ``k // N`` for frame ``k``."""
    from generator.spec.towns import first_frame, frames_by_town, redraw_every, town_spec

    if redraw_every(spec) is None:
        return [(spec, 0, sorted(frames))]
    return [(town_spec(spec, i), first_frame(spec, i), ks) for i, ks in frames_by_town(spec, frames).items()]


def _remove_unfinished(out: Path, plan, created: bool) -> None:
    """After a failed run: drop the files of images without metadata (an image is done when its JSON
    exists) and temporaries; a folder this run created and that holds no finished image goes too."""
    try:
        for name in plan.images():
            if not image_path(out, name, ".json").exists():
                for suffix in (".exr", "_preview.png"):
                    image_path(out, name, suffix).unlink(missing_ok=True)
        for folder in sorted({image_dir(out, k) for k in plan.frames}):
            for tmp in folder.glob(f"{TMP_PREFIX}*") if folder.is_dir() else ():
                tmp.unlink(missing_ok=True)
        if created and not has_images(out, "*.json"):
            shutil.rmtree(out, ignore_errors=True)
    except OSError as e:  # the failure being reported matters more than this cleanup
        log.warning("could not remove the unfinished images of the failed run: %s", e)
