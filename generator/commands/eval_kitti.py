"""``urbangen eval --detection kitti --pred DIR --gt DIR``: KITTI 3D object AP R40.

The metric is :mod:`generator.stats.detection_kitti`.

``--gt``: a KITTI ``label_2`` folder, or a KITTI export root (``training/label_2``; with
``--split NAME`` only the samples of ``ImageSets/NAME.txt``). ``--pred``: a folder of KITTI result
files (``NNNNNN.txt``, 16 fields: the label fields and a score), one for every ground-truth file
evaluated (an empty file: no detections). Prints AP R40 of 2D boxes, bird's eye view and 3D boxes,
and AOS, at easy / moderate / hard, and writes them as JSON. Bad input (a truncated line, a NaN,
an unknown type, a missing file) stops with one line naming the file and field, exit 2, nothing written.
"""

from __future__ import annotations

import re

from generator.atomic import write_json
from generator.commands.preflight import input_dir, output_file
from generator.errors import UserError
from generator.safeload import read_text

_NAME = re.compile(r"^[0-9]{6}\.txt$")
KITTI_CLASSES = ("Car", "Pedestrian", "Cyclist", "Van", "Person_sitting", "Truck")


def _gt_files(gt, split: str | None):
    label_dir = gt / "training" / "label_2" if (gt / "training" / "label_2").is_dir() else gt
    if split is not None:
        sets = gt / "ImageSets" / f"{split}.txt"
        if not sets.is_file():
            raise UserError(f"{sets}: missing (--split names ImageSets/<split>.txt of a KITTI export root)")
        ids = read_text(sets).split()
        if not all(re.fullmatch(r"[0-9]{6}", i) for i in ids):
            raise UserError(f"{sets}: every line must be a six-digit sample id")
        return label_dir, [f"{i}.txt" for i in ids]
    names = sorted(p.name for p in label_dir.iterdir() if _NAME.match(p.name))
    if not names:
        raise UserError(f"{label_dir}: no KITTI label files (NNNNNN.txt)")
    return label_dir, names


def run(args) -> int:
    from generator.formats.kitti_object import read_labels
    from generator.stats.detection_kitti import Frame, evaluate, format_result

    input_dir(args.gt, "--gt")
    input_dir(args.pred, "--pred")
    classes = list(dict.fromkeys(args.classes or ("Car", "Pedestrian", "Cyclist")))
    bad = [c for c in classes if c not in KITTI_CLASSES]
    if bad:
        raise UserError(f"--classes: {', '.join(bad[:3])}: KITTI AP evaluates {', '.join(KITTI_CLASSES)}")
    out = output_file(args.json or args.pred / "eval_kitti.json", "--json")
    label_dir, names = _gt_files(args.gt, args.split)
    gts, dts = [], []
    for name in names:
        pred = args.pred / name
        if not pred.is_file():
            raise UserError(f"{pred}: missing (every evaluated sample needs a result file; empty for none)")
        gts.append(Frame.of(read_labels(label_dir / name)))
        dts.append(Frame.of(read_labels(pred, predictions=True)))
    result = evaluate(gts, dts, classes)
    doc = {"metric": "KITTI AP R40 (and R11), percent", "gt": str(args.gt), "pred": str(args.pred),
           "samples": len(names), "classes": result}
    write_json(out, doc)
    print(format_result(result))
    print(f"wrote {out}")
    return 0
