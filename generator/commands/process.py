"""``urbangen process DIR OUT --domain-gap seed002 [--dropout F] [--jitter-m M] [--gap-intensity V]``.

Writes the processed twin of a dataset into OUT: the same scenes, images, poses and boxes, every scan
through seed 002's domain-gap processing (10 % of the points removed, +-0.05 m uniform jitter per axis,
constant intensity 1 of 255), with every point count that follows (labels, side files, lidar_meta.json,
semantic-kitti.yaml, the box file's and OpenLABEL's num_lidar_pts) recounted, so raw and processed evaluations run on
identical scenes. The parts can be changed one by one. Nothing is written on error.
"""

from __future__ import annotations

from generator.commands.options import Number, path
from generator.commands.preflight import input_dir, output_dir
from generator.errors import UserError


def register(sub) -> None:
    from generator.scan_effects.domain_gap import PRESETS

    p = sub.add_parser("process", help="the processed twin of a dataset (seed 002 domain-gap processing)",
                       description=__doc__.split("\n\n")[1])
    p.add_argument("dataset", type=path, help="dataset folder (lidar/sequences/NN inside)")
    p.add_argument("out", type=path, help="folder of the twin (new, or without lidar/, images/, openlabel/)")
    p.add_argument("--domain-gap", required=True, choices=[k for k in PRESETS if k != "none"],
                   help="the processing: seed002 (10%% removal, +-0.05 m jitter, intensity 1/255)")
    p.add_argument("--dropout", type=Number(0, 1, below=True), default=None, help="fraction removed, in [0, 1)")
    p.add_argument("--jitter-m", type=Number(0, 1), default=None, help="uniform per-axis jitter half-width, m")
    p.add_argument("--gap-intensity", type=Number(0, 1, none=True), default=None,
                   help="constant remission in [0, 1] ('none' keeps the scans' own)")
    p.set_defaults(func=run)


def run(args) -> int:
    import dataclasses

    from generator.jobs.process import process_dataset
    from generator.scan_effects.domain_gap import preset

    root = input_dir(args.dataset, what="dataset folder")
    output_dir(args.out, "OUT")
    if args.out.resolve() == root.resolve():
        raise UserError(f"{args.out}: the twin must go into another folder")
    gap = preset(args.domain_gap)
    parts = {k: v for k, v in (("dropout", args.dropout), ("jitter_m", args.jitter_m)) if v is not None}
    if args.gap_intensity is not None:
        parts["constant_intensity"] = None if args.gap_intensity == "none" else args.gap_intensity
    gap = dataclasses.replace(gap, **parts)
    summary = process_dataset(root, args.out, gap)
    kept = summary["points_out"] / max(summary["points_in"], 1)
    print(f"wrote the processed twin of {root} to {args.out}: {len(summary['sequences'])} sequence(s), "
          f"{summary['points_out']} of {summary['points_in']} points kept ({100 * kept:.1f} %), "
          f"jitter +-{gap.jitter_m} m, intensity {gap.constant_intensity}; {summary['box_records']} box records "
          f"recounted ({summary['boxes_dropped']} left without points dropped)")
    return 0
