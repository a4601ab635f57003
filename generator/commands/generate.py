"""``urbangen generate SPEC --config CFG --out DIR [--frames N] [--variants V] [--workers N] [--executor local|ray]``.

The main job: a whole dataset from one spec -- images of every frame in every
weather x time-of-day combination (balanced like seed 003 Table II), one labelled
LiDAR sequence sharing the frames and their weather, OpenLABEL boxes, statistics and a
manifest. Rerunning the same command resumes an interrupted run.
"""

from __future__ import annotations

import logging
from pathlib import Path

from generator.commands.render import add_render_arguments, positive
from generator.errors import UserError
from generator.jobs.executors import EXECUTORS
from generator.jobs.generate import GenerateOptions, run_generate
from generator.jobs.plan import make_plan
from generator.jobs.variants import parse_combos
from generator.spec import load_spec
from generator.spec.render import load_render_config

log = logging.getLogger(__name__)


def register(sub) -> None:
    p = sub.add_parser("generate", help="the main job: images x weather + LiDAR + boxes + stats, resumable",
                       description=__doc__.split("\n\n")[1])
    add_render_arguments(p, "dataset folder (created; a rerun resumes it)", frames=2, variants="all")
    p.add_argument("--sequence", default="00", help="SemanticKITTI sequence id of the scans (default 00)")
    p.add_argument("--executor", default="local", help="local (default) or ray")
    p.add_argument("--ray-address", default=None, help="address of an existing Ray cluster (default: start a local one)")
    p.set_defaults(func=run)


def run(args) -> int:
    spec = load_spec(args.spec)
    cfg = load_render_config(args.config)
    positive("frames", args.frames)
    positive("workers", args.workers)
    if args.executor not in EXECUTORS:
        raise UserError(f"--executor: must be one of {', '.join(EXECUTORS)}, got {args.executor!r}")
    if not (args.sequence.isdigit() and len(args.sequence) <= 2):
        raise UserError(f"--sequence: must be a number 0..99 (e.g. 00), got {args.sequence!r}")
    try:
        combos = parse_combos(args.variants)
    except ValueError as e:
        raise UserError(f"--variants: {e}") from None
    out: Path = args.out
    if out.exists() and not out.is_dir():
        raise UserError(f"--out: {out} exists and is not a folder")
    plan = make_plan(args.frames, combos=combos, sequence=f"{int(args.sequence):02d}")
    run_rec = run_generate(spec, cfg, GenerateOptions(out, plan, args.workers, args.executor, args.ray_address))
    rate = run_rec.get("images_per_hour")
    print(f"dataset in {out}: {len(plan.frames)} frames x {len(plan.combos)} variants, LiDAR sequence {plan.sequence}"
          + (f"; {rate:.0f} images/hour" if rate else "; nothing left to render"))
    return 0
