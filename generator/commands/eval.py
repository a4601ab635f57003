"""``urbangen eval --pred DIR --gt DIR [--labels unified11|semantickitti|native] [--sequences NN ...] [--json PATH]``.

Compares two SemanticKITTI-layout label trees scan by scan (``sequences/NN/labels/*.label``),
prints IoU per class and the mIoU (seed 000 Eq. 11-12; class 0 ignored as in SemanticKITTI;
classes absent from both prediction and ground truth are left out of the mean and listed),
and writes the result as JSON (default ``PRED/eval_<labels>.json``).
"""

from __future__ import annotations

from pathlib import Path

from generator.atomic import write_json
from generator.errors import UserError


def register(sub) -> None:
    from generator.stats.evaluate import LABEL_SETS

    p = sub.add_parser("eval", help="IoU per class and mIoU of predicted labels against ground truth",
                       description=__doc__.split("\n\n")[1])
    p.add_argument("--pred", required=True, type=Path, help="prediction root (sequences/NN/labels/)")
    p.add_argument("--gt", required=True, type=Path, help="ground-truth root (sequences/NN/labels/)")
    p.add_argument("--labels", default="unified11", choices=LABEL_SETS,
                   help="label set (default unified11; native needs native_labels/ in both trees)")
    p.add_argument("--sequences", nargs="+", default=None, help="sequences to evaluate (default: all of --gt)")
    p.add_argument("--json", type=Path, default=None, help="result file (default PRED/eval_<labels>.json)")
    p.set_defaults(func=run)


def run(args) -> int:
    from generator.formats.semantickitti import sequence_name
    from generator.stats.evaluate import evaluate_trees, format_table

    for flag, path in (("--pred", args.pred), ("--gt", args.gt)):
        if not path.is_dir():
            raise UserError(f"{flag}: {path} is not a folder")
    seqs = None if args.sequences is None else [sequence_name(s) for s in args.sequences]
    result = evaluate_trees(args.pred, args.gt, args.labels, seqs)
    result["pred"], result["gt"] = str(args.pred), str(args.gt)
    out = args.json or args.pred / f"eval_{args.labels}.json"
    write_json(out, result)
    print(format_table(result))
    print(f"wrote {out}")
    return 0
