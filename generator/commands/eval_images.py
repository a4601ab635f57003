"""``urbangen eval --images --pred PRED --gt DIR [--label-set SET] [--split val] [--sequences NN]``.

Scores predicted image label maps against ground truth exactly as cityscapesScripts'
evalPixelLevelSemanticLabeling does (:mod:`generator.stats.image_eval`): PRED is a folder of label PNGs
(any depth), DIR a Cityscapes export (``gtFine/<split>/``) or a dataset (its images and the KITTI stream
of sequence NN; :mod:`generator.stats.image_sources`). Each ground-truth image takes the prediction
named ``<city>_<seq>_<frame>*.png`` (Cityscapes stems) or its ``image_2`` file name; images without one
are skipped and counted. Predictions in another label set (--label-set cityscapes_trainids, native or a
YAML file) are mapped to Cityscapes label ids first, which the set must determine.
"""

from __future__ import annotations

import logging

from generator.commands.preflight import input_dir, output_file
from generator.errors import UserError
from generator.safeload import printable

log = logging.getLogger(__name__)


def add_image_args(p) -> None:
    """The options only ``--images`` reads."""
    from generator.labels.class_sets import BUILTIN

    p.add_argument("--label-set", default="cityscapes", metavar="SET",
                   help=f"--images: what the predicted pixel values are: {', '.join(BUILTIN)} or a label-set "
                        "YAML file (default cityscapes: label ids)")


def run_images(args) -> int:
    from generator.atomic import write_json
    from generator.formats.label_png import check_ids, read_label_png
    from generator.formats.prediction_files import PredictionFolder
    from generator.labels.class_sets import builtin_sets, load_class_set, translate
    from generator.progress import progress
    from generator.stats.image_eval import PixelEvaluator, format_table
    from generator.stats.image_sources import ground_truth

    if args.panoptic:
        raise UserError("--panoptic: scores scans; it cannot be combined with --images")
    from generator.formats.cityscapes import DEFAULT_SPLIT, SPLITS

    split = args.split or DEFAULT_SPLIT
    if split not in SPLITS:
        raise UserError(f"--split: --images scores a Cityscapes split folder, one of {', '.join(SPLITS)}; got "
                        f"{printable(split)}")
    seqs = args.sequences or ["00"]
    if len(set(seqs)) != 1:
        raise UserError("--sequences: --images reads the KITTI stream of one sequence; name one")
    pred_set = load_class_set(args.label_set)
    to_cs = translate(pred_set, builtin_sets()["cityscapes"])
    if to_cs is None:
        raise UserError(f"--label-set: {pred_set.name} has classes that span several Cityscapes label ids; "
                        "its predictions cannot be scored as Cityscapes label maps")
    input_dir(args.pred, "--pred")
    input_dir(args.gt, "--gt")
    out = output_file(args.json or args.pred / "eval_images.json", "--json")
    gts = ground_truth(args.gt, split, seqs[0])
    folder = PredictionFolder(args.pred)
    pairs = [(g, folder.by_stem(g.name) if g.by == "stem" else folder.by_name(g.name)) for g in gts]
    matched = [(g, p) for g, p in pairs if p is not None]
    if not matched:
        raise UserError(f"{args.pred}: --pred: no prediction for any of the {len(gts)} ground-truth images "
                        f"(expected names like {gts[0].name}{'*' if gts[0].by == 'stem' else ''}.png)")
    ev = PixelEvaluator()
    for g, p in progress(matched, desc="eval images", unit="image"):
        gt, inst = g.load()
        raw = read_label_png(p, gt.shape)
        check_ids(raw, pred_set.known, p, pred_set.name)
        ev.add(g.name, gt, to_cs[raw], inst, str(p))
    result = ev.result()
    missing = [g.name for g, p in pairs if p is None]
    result.update({"pred": str(args.pred), "gt": str(args.gt), "label_set": pred_set.name,
                   "ground_truth_without_prediction": missing,
                   "predictions_without_ground_truth": [str(p) for p in folder.unused()]})
    write_json(out, result)
    print(format_table(result))
    if missing:
        print(f"{len(missing)} of {len(gts)} ground-truth images have no prediction and were skipped "
              f"(listed in the JSON)")
    print(f"wrote {out}")
    return 0
