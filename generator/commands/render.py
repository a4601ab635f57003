"""``urbangen render SPEC --config CFG --out DIR [--frames N] [--variants V] [--workers N] [--executor local|ray]``.

Renders frames along the scene's route: per image one multilayer EXR (RGB + one mask
channel per class + depth + instance), a metadata JSON and a preview PNG, in
``DIR/images/``. ``--variants all`` renders the 12 weather x time-of-day combinations
of every frame (4 RGB renders; fog and rain in post). Images whose metadata already
exists are skipped (rerun = resume).
"""

from __future__ import annotations

import logging
import shutil
from pathlib import Path

from dataclasses import dataclass

from generator.errors import UserError
from generator.jobs.executors import EXECUTORS, make_jobs, run_jobs
from generator.jobs.images import image_name
from generator.jobs.variants import parse_combos
from generator.spec import load_spec
from generator.spec.render import load_render_config

log = logging.getLogger(__name__)


def add_render_arguments(p, out_help: str, frames: int, variants: str) -> None:
    """The options ``render`` and ``generate`` share (with their own defaults)."""
    p.add_argument("spec", help="scene spec JSON (e.g. scenes/default_town.json)")
    p.add_argument("--config", required=True, help="render config YAML or preset name (test, preview, paper)")
    p.add_argument("--out", required=True, type=Path, help=out_help)
    p.add_argument("--frames", type=int, default=frames, help=f"frames along the route (default {frames})")
    p.add_argument("--variants", default=variants,
                   help=f"all (12 weather x time combinations per frame), clear (day, clear), or pairs like "
                        f"day:fog,night:rain (default {variants})")
    p.add_argument("--workers", type=int, default=1, help="parallel Blender processes (default 1)")
    p.add_argument("--executor", default="local", choices=EXECUTORS,
                   help="where the render workers run: local (spawned processes, default) or ray")
    p.add_argument("--ray-address", default=None, help="address of an existing Ray cluster (default: start a local one)")


def register(sub) -> None:
    p = sub.add_parser("render", help="render RGB + label EXRs with metadata along the route",
                       description=__doc__.split("\n\n")[1])
    add_render_arguments(p, "output folder", frames=2, variants="clear")
    p.add_argument("--first", type=int, default=0, help="index of the first frame (default 0)")
    p.set_defaults(func=run)


def positive(name: str, value: int, minimum: int = 1) -> int:
    """Check an integer option; a bad one is a one-line user error."""
    if value < minimum:
        raise UserError(f"--{name}: must be an integer >= {minimum}, got {value}")
    return value


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
    positive("frames", args.frames)
    positive("workers", args.workers)
    out: Path = args.out
    if out.exists() and not out.is_dir():
        raise UserError(f"--out: {out} exists and is not a folder")
    try:
        combos = parse_combos(args.variants)
    except ValueError as e:
        raise UserError(f"--variants: {e}") from None
    return RenderArgs(spec, cfg, out, combos)


def run(args) -> int:
    r = check_render_args(args)
    positive("first", args.first, 0)
    out, combos = r.out, r.combos
    todo = [k for k in range(args.first, args.first + args.frames)
            if not all((out / "images" / f"{image_name(k, t, w)}.json").exists() for t, w in combos)]
    if not todo:
        log.info("all %d frames already rendered in %s", args.frames, out)
        return 0
    jobs = make_jobs(r.spec, r.cfg, out, todo, combos, args.workers)
    res = run_jobs(args.executor, jobs, len(todo), None, args.ray_address)
    shutil.rmtree(out / ".scratch", ignore_errors=True)
    n = sum(len(msg["images"]) for msg in res.frame_seconds.values())
    print(f"rendered {n} images of {len(res.frame_seconds)} frames into {out / 'images'} in {res.wall_s:.1f} s")
    return 0
