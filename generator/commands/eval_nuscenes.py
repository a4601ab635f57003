"""``urbangen eval --detection nuscenes --pred FILE --gt DIR [--split NAME] [--classes ...] [--json PATH]``.

The metric itself is :mod:`generator.stats.detection_nuscenes` (nuscenes-devkit's DetectionEval).
"""

from __future__ import annotations

from generator.atomic import write_json
from generator.commands.preflight import input_dir, input_file, output_file


def run(args) -> int:
    from generator.stats import detection_nuscenes as metric

    pred, gt = input_file(args.pred, "--pred", "predictions file"), input_dir(args.gt, "--gt")
    out = output_file(args.json or pred.with_name(f"{pred.name}.eval_nuscenes.json"), "--json")
    classes = args.classes[0] if args.classes == ["all"] else args.classes
    result = metric.evaluate(pred, gt, args.split, classes)
    result["pred"], result["gt"] = str(pred), str(gt)
    write_json(out, result)
    print(metric.format_result(result))
    print(f"wrote {out}")
    return 0
