"""``urbangen eval --pred DIR --gt DIR [--labels unified11|semantickitti|native] [--panoptic] [--json PATH]``;
``urbangen eval --detection kitti|nuscenes --pred PRED --gt DIR [--split NAME] [--classes ...] [--json PATH]``.

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
is written as JSON (default PRED/eval_<labels>.json). --detection scores 3D boxes instead: kitti
(AP R40, generator.commands.eval_kitti) or nuscenes (--pred a nuScenes results file, --gt an 'urbangen
export nuscenes' dataroot; mAP, NDS and the TP errors computed by nuscenes-devkit itself, pip install
-e ".[detection]"; generator.commands.eval_nuscenes). --images scores predicted image label
maps (PNGs in PRED, any label set) against a Cityscapes export or a dataset's images as
cityscapesScripts does: IoU and iIoU per class and category, their averages, per image, and
seed 001's per-image table (default PRED/eval_images.json).
"""

from __future__ import annotations

from generator.atomic import write_json
from generator.commands.eval_images import add_image_args, run_images
from generator.commands.options import Integer, path, sequence_id
from generator.commands.preflight import input_dir, output_file
from generator.formats.semantickitti import semantickitti_root

#: Largest --min-points (a segment of more points than a scan holds never counts).
MAX_MIN_POINTS = 10_000_000
#: ``--detection`` benchmark -> the module whose ``run(args)`` evaluates it.
DETECTION = {"kitti": "generator.commands.eval_kitti", "nuscenes": "generator.commands.eval_nuscenes"}


def register(sub) -> None:
    from generator.stats.evaluate import LABEL_SETS, MEAN_OVER
    from generator.stats.panoptic import MIN_POINTS

    p = sub.add_parser("eval", help="IoU per class and mIoU (and PQ) of predicted labels against ground truth",
                       description=__doc__.split("\n\n")[1])
    p.add_argument("--pred", required=True, type=path,
                   help="prediction root (sequences/NN/predictions/ or sequences/NN/labels/; with --images: a "
                        "folder of label PNGs)")
    p.add_argument("--gt", required=True, type=path,
                   help="ground-truth root (sequences/NN/labels/; with --images: a Cityscapes export or a dataset)")
    p.add_argument("--images", action="store_true",
                   help="score image label maps (cityscapesScripts conventions) instead of scans")
    add_image_args(p)
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
    p.add_argument("--detection", choices=sorted(DETECTION), default=None,
                   help="evaluate 3D object detections instead: kitti (AP R40; --gt a label_2 folder or a KITTI "
                        "export root, --pred a folder of KITTI result files) or nuscenes (mAP, NDS and TP errors "
                        "by nuscenes-devkit; --gt an 'urbangen export nuscenes' dataroot, --pred a results JSON)")
    p.add_argument("--classes", nargs="+", default=None,
                   help="--detection kitti: classes (default Car Pedestrian Cyclist); nuscenes: detection classes "
                        "scored (default: those in the ground truth of the split; 'all': nuScenes' ten)")
    p.add_argument(
        "--split",
        default=None,
        help="--detection kitti: only the samples of GT/ImageSets/SPLIT.txt (e.g. val); nuscenes: a split "
        "of GT/v1.0-*/splits.json (default urbangen_val when it has scenes, else urbangen_all); "
        "--images with a Cityscapes export: the split folder scored (default val, as cityscapesScripts)",
    )
    p.set_defaults(func=run)


def run(args) -> int:
    if args.images:
        return run_images(args)
    if args.detection is not None:
        import importlib

        return importlib.import_module(DETECTION[args.detection]).run(args)
    from generator.stats.evaluate import evaluate_trees, format_table
    from generator.stats.panoptic import format_panoptic

    for flag, folder in (("--pred", args.pred), ("--gt", args.gt)):
        input_dir(folder, flag)
    args.gt = semantickitti_root(args.gt)  # a dataset folder's lidar/ or a SemanticKITTI root
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
