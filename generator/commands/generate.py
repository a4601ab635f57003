"""``urbangen generate SPEC --config CFG --out DIR [--frames N] [--variants V] [--workers N] [--executor local|ray]``.

The main job: a whole dataset from one spec -- images of every frame in every
weather x time-of-day combination (balanced like seed 003 Table II), one labelled
LiDAR sequence sharing the frames and their weather, OpenLABEL boxes, statistics and a
manifest. Rerunning the same command resumes an interrupted run.
"""

from __future__ import annotations

import logging

from generator.commands.options import sequence_id
from generator.commands.render import add_render_arguments, check_render_args
from generator.formats.label_config import SPLITS
from generator.jobs.generate import GenerateOptions, run_generate
from generator.jobs.plan import make_plan

log = logging.getLogger(__name__)


def register(sub) -> None:
    p = sub.add_parser("generate", help="the main job: images x weather + LiDAR + boxes + stats, resumable",
                       description=__doc__.split("\n\n")[1])
    add_render_arguments(p, "dataset folder (created; a rerun resumes it)", frames=2, variants="all")
    p.add_argument("--sequence", type=sequence_id, default="00",
                   help="SemanticKITTI sequence id of the scans, 00..999999 (default 00)")
    p.add_argument("--split", default=None, choices=SPLITS,
                   help="split of the run's sequences in DIR/lidar/semantic-kitti.yaml: train, valid or test (default: "
                        "the one they have there, else valid, what semantic-kitti-api evaluates without -s)")
    p.add_argument("--plan-only", action="store_true",
                   help="check the whole plan (limits, the first town's route, the disk it needs) and print it; "
                        "write nothing")
    p.set_defaults(func=run)


def run(args) -> int:
    r = check_render_args(args)
    out = r.out
    plan = make_plan(args.frames, combos=r.combos, sequence=args.sequence)
    opts = GenerateOptions(out, plan, args.workers, args.executor, args.ray_address, args.split, args.plan_only)
    run_rec = run_generate(r.spec, r.cfg, opts)
    if args.plan_only:
        seqs = run_rec["sequences"]
        print(f"plan for {out}: {run_rec['frames']} frames, {run_rec['images']} images, {run_rec['towns']} town(s), "
              f"LiDAR sequence(s) {seqs[0]}" + (f"..{seqs[1]}" if seqs[1] != seqs[0] else "")
              + f"; writes about {run_rec['disk']} ({run_rec['writes']}); fits the free space; nothing written")
        return 0
    towns = run_rec.get("towns")
    rate = run_rec.get("images_per_hour")
    seqs = f"LiDAR sequence {plan.sequence}" if not towns else \
        f"{towns['count']} towns, LiDAR sequences {towns['sequences'][0]}..{towns['sequences'][1]}"
    print(f"dataset in {out}: {len(plan.frames)} frames x {len(plan.combos)} variants, {seqs}"
          + (f"; {rate:.0f} images/hour" if rate else "; nothing left to render"))
    return 0
