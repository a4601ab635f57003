"""``urbangen eval --pred DIR --gt DIR [--labels unified11|semantickitti|native] [--panoptic] [--json PATH]``.

Compares two SemanticKITTI-layout label trees scan by scan and prints IoU per class and
the mIoU exactly as semantic-kitti-api's evaluate_semantics.py computes them: confusion
[prediction, ground truth]; class 0 (unlabeled) ignored only as ground truth, so a labelled
point predicted 0 is a false negative of its class; the mIoU averages every class of the
label set except 0 -- 11 classes for unified11, 19 for semantickitti, 19 for native (sky
included) -- and a class absent from both prediction and ground truth counts as IoU 0.
--mean-over present averages only the classes present in either. Predictions are read from
PRED/sequences/NN/predictions/ when that folder exists (the reference's layout), else from
labels/. --panoptic adds PQ, SQ and RQ per class and their means (SemanticKITTI panoptic:
segments matched at IoU > 0.5, unmatched segments under --min-points ignored). The result
is written as JSON (default PRED/eval_<labels>.json).
"""

from __future__ import annotations

from generator.atomic import write_json
from generator.commands.options import Integer, path, sequence_id
from generator.commands.preflight import input_dir, output_file

#: Largest --min-points (a segment of more points than a scan holds never counts).
MAX_MIN_POINTS = 10_000_000


def register(sub) -> None:
    from generator.stats.evaluate import LABEL_SETS, MEAN_OVER
    from generator.stats.panoptic import MIN_POINTS

    p = sub.add_parser("eval", help="IoU per class and mIoU (and PQ) of predicted labels against ground truth",
                       description=__doc__.split("\n\n")[1])
    p.add_argument("--pred", required=True, type=path,
                   help="prediction root (sequences/NN/predictions/ or sequences/NN/labels/)")
    p.add_argument("--gt", required=True, type=path, help="ground-truth root (sequences/NN/labels/)")
    p.add_argument("--labels", default="unified11", choices=LABEL_SETS,
                   help="label set: unified11, semantickitti or native (default unified11; native needs "
                        "native_labels/ in both trees)")
    p.add_argument("--sequences", nargs="+", type=sequence_id, default=None,
                   help="sequences to evaluate, 00..999999 (default: all of --gt)")
    p.add_argument("--mean-over", default="all", choices=MEAN_OVER,
                   help="classes the means average: all (every class but 0, absent ones as 0; the reference, "
                        "default) or present (only classes in prediction or ground truth)")
    p.add_argument("--panoptic", action="store_true", help="also panoptic quality: PQ, SQ, RQ per class and mean")
    p.add_argument("--min-points", type=Integer(1, MAX_MIN_POINTS), default=MIN_POINTS,
                   help=f"panoptic: smallest unmatched segment counted as FP/FN, 1..{MAX_MIN_POINTS} "
                        f"(default {MIN_POINTS}, as the reference)")
    p.add_argument("--json", type=path, default=None, help="result file (default PRED/eval_<labels>.json)")
    p.set_defaults(func=run)


def run(args) -> int:
    from generator.stats.evaluate import evaluate_trees, format_table
    from generator.stats.panoptic import format_panoptic

    for flag, folder in (("--pred", args.pred), ("--gt", args.gt)):
        input_dir(folder, flag)
    out = output_file(args.json or args.pred / f"eval_{args.labels}.json", "--json")
    seqs = None if args.sequences is None else list(dict.fromkeys(args.sequences))
    result = evaluate_trees(args.pred, args.gt, args.labels, seqs, mean_over=args.mean_over,
                            panoptic=args.panoptic, min_points=args.min_points)
    result["pred"], result["gt"] = str(args.pred), str(args.gt)
    write_json(out, result)
    print(format_table(result))
    if args.panoptic:
        print(format_panoptic(result["panoptic"]))
    print(f"wrote {out}")
    return 0
