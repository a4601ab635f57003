"""nuScenes detection metrics, computed by nuscenes-devkit itself (``urbangen eval --detection nuscenes``).

Ground truth is a nuScenes dataroot (``urbangen export nuscenes``'s output: ``GT/v1.0-*/`` tables and
``splits.json``); predictions are a nuScenes detection results file::

    {"meta": {...}, "results": {"<sample_token>": [{"sample_token", "translation": [x, y, z],
     "size": [w, l, h], "rotation": [w, x, y, z], "velocity": [vx, vy], "detection_name",
     "detection_score", "attribute_name"}, ...], ...}}

(global frame, metres, m/s; every sample of the split present, an empty list where nothing was
detected). The file is checked here first -- every sample token one of the split's, every number
finite, every class a nuScenes detection class (those not scored here are ignored, as the devkit
ignores them), sizes positive, rotations non-zero, at most 500 boxes
per sample -- so a bad file is one line naming the file and the field, and nothing is written. Then
:class:`nuscenes.eval.detection.evaluate.DetectionEval` runs on it unchanged: AP at 0.5, 1, 2 and 4 m
centre distance per class, mAP, the true-positive errors ATE, ASE, AOE, AVE, AAE and NDS.

The configuration is the devkit's ``detection_cvpr_2019`` (class ranges, thresholds, min recall and
precision) with its ``class_names`` restricted to the classes evaluated (default: the detection classes
with a ground-truth box the evaluation keeps -- within the class's range, with points -- so a class
urbangen did not draw, or drew only beyond 40 or 50 m, does not count as AP 0;
``classes="all"`` keeps nuScenes' ten). The split is one of ``splits.json`` (the devkit's custom
splits); default ``urbangen_val`` when it has scenes, else ``urbangen_all``.
"""

from __future__ import annotations

import contextlib
import io
import json
import logging
import math
import os
import tempfile
from pathlib import Path

from generator import safeload
from generator.errors import UserError

log = logging.getLogger(__name__)

INSTALL_HINT = 'nuScenes evaluation needs nuscenes-devkit: pip install -e ".[detection]"'
#: Largest predictions file read (a full nuScenes val submission is about 0.5 GB).
MAX_PRED_BYTES = 2 * 1024**3
DEFAULT_SPLITS = ("urbangen_val", "urbangen_all")
TP_NAMES = {"trans_err": "mATE", "scale_err": "mASE", "orient_err": "mAOE", "vel_err": "mAVE", "attr_err": "mAAE"}


def devkit():
    """The devkit's modules (``NuScenes``, the detection evaluation), or one line saying how to install it."""
    try:
        from nuscenes import NuScenes
        from nuscenes.eval.common.config import config_factory
        from nuscenes.eval.detection.constants import ATTRIBUTE_NAMES, DETECTION_NAMES
        from nuscenes.eval.detection.evaluate import DetectionEval
    except ImportError:
        raise UserError(INSTALL_HINT) from None
    return NuScenes, config_factory, DetectionEval, DETECTION_NAMES, ATTRIBUTE_NAMES


@contextlib.contextmanager
def _quiet():
    """The devkit prints progress to stdout and stderr: keep it out of urbangen's one-line output."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        yield
    for line in (out.getvalue() + err.getvalue()).splitlines():
        if line.strip():
            log.debug("devkit: %s", line.strip())


def version_of(gt: Path) -> str:
    """The one ``v1.0-*`` table folder of a nuScenes dataroot."""
    found = sorted(p.name for p in Path(gt).glob("v1.0-*") if (p / "sample.json").is_file())
    if len(found) != 1:
        raise UserError(f"{gt}: needs exactly one nuScenes table folder v1.0-*/ with sample.json "
                        f"(found {', '.join(found) or 'none'}); is it an 'urbangen export nuscenes' output?")
    return found[0]


def load_ground_truth(gt: Path, split: str | None = None):
    """``(nusc, split, sample_tokens)``: the devkit's database of ``gt`` and the samples of the split."""
    NuScenes = devkit()[0]
    from nuscenes.eval.common.loaders import get_samples_of_custom_split

    version = version_of(gt)
    splits_path = Path(gt) / version / "splits.json"
    splits = safeload.load_json(splits_path, max_bytes=safeload.MAX_METADATA_BYTES, max_nodes=10_000_000) \
        if os.path.lexists(splits_path) else {}
    if not isinstance(splits, dict):
        raise UserError(f"{splits_path}: must map split names to lists of scene names")
    if split is None:
        split = next((s for s in DEFAULT_SPLITS if splits.get(s)), None)
        if split is None:
            raise UserError(f"{splits_path}: no split {' or '.join(DEFAULT_SPLITS)} with scenes; name one with --split")
    elif split not in splits:
        raise UserError(f"--split: {safeload.printable(split, 60)} is not a split of {splits_path} "
                        f"(has {', '.join(map(str, splits)) or 'none'})")
    try:
        with _quiet():
            nusc = NuScenes(version=version, dataroot=str(gt), verbose=False)
            tokens = get_samples_of_custom_split(split_name=split, nusc=nusc)
    except (AssertionError, KeyError, ValueError, OSError, json.JSONDecodeError) as e:
        raise UserError(f"{gt / version}: the devkit cannot load it ({type(e).__name__}); "
                        "is it an 'urbangen export nuscenes' output?") from None
    if not tokens:
        raise UserError(f"{splits_path}: split {split} has no samples")
    return nusc, split, tokens


def _bad(path: Path, where: str, reason: str) -> UserError:
    return UserError(f"{safeload.printable(path, 300)}: {where}: {reason}")


def _numbers(value, n: int, path: Path, where: str, positive: bool = False) -> None:
    if not (isinstance(value, list) and len(value) == n):
        raise _bad(path, where, f"must be a list of {n} numbers")
    for i, v in enumerate(value):
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise _bad(path, f"{where}[{i}]", f"must be a finite number, got {safeload.printable(repr(v), 30)}")
        if positive and v <= 0:
            raise _bad(path, f"{where}[{i}]", "must be > 0 (a size in metres)")


def read_predictions(path: Path, sample_tokens: list[str], classes: list[str], max_boxes: int) -> dict:
    """The checked results file (see the module docstring for what is checked).

    Returns
    -------
    dict
        The parsed file, unchanged.
    """
    _, _, _, detection_names, attribute_names = devkit()
    text = safeload.read_text(path, max_bytes=MAX_PRED_BYTES)
    try:
        data = json.loads(text, parse_constant=float)   # NaN / Infinity reach the checks below, which name the field
    except json.JSONDecodeError as e:
        raise UserError(f"{safeload.printable(path, 300)}: invalid JSON at line {e.lineno} column {e.colno}") from None
    except RecursionError:
        raise UserError(f"{safeload.printable(path, 300)}: invalid JSON: nested too deep") from None
    if not isinstance(data, dict) or not isinstance(data.get("results"), dict):
        raise _bad(path, "results", "must be an object mapping sample tokens to lists of boxes")
    if not isinstance(data.get("meta", {}), dict):
        raise _bad(path, "meta", "must be an object")
    results, wanted = data["results"], set(sample_tokens)
    for tok in results:
        if tok not in wanted:
            raise _bad(path, f"results.{safeload.printable(tok, 40)}", "not a sample token of the evaluated split")
    missing = [t for t in sample_tokens if t not in results]
    if missing:
        raise _bad(path, f"results.{missing[0]}", f"missing: every sample of the split needs a list (empty when "
                                                  f"nothing was detected); {len(missing)} of {len(wanted)} missing")
    for tok, boxes in results.items():
        at = f"results.{tok}"
        if not isinstance(boxes, list):
            raise _bad(path, at, "must be a list of boxes")
        if len(boxes) > max_boxes:
            raise _bad(path, at, f"{len(boxes)} boxes; the nuScenes evaluation allows at most {max_boxes} per sample")
        for i, b in enumerate(boxes):
            where = f"{at}[{i}]"
            if not isinstance(b, dict):
                raise _bad(path, where, "must be an object")
            if b.get("sample_token") != tok:
                raise _bad(path, f"{where}.sample_token", "must be the sample token it is listed under")
            _numbers(b.get("translation"), 3, path, f"{where}.translation")
            _numbers(b.get("size"), 3, path, f"{where}.size", positive=True)
            _numbers(b.get("rotation"), 4, path, f"{where}.rotation")
            if math.fsum(v * v for v in b["rotation"]) < 1e-12:
                raise _bad(path, f"{where}.rotation", "must be a non-zero quaternion [w, x, y, z]")
            _numbers(b.get("velocity"), 2, path, f"{where}.velocity")
            name = b.get("detection_name")
            if name not in detection_names:
                raise _bad(path, f"{where}.detection_name", f"{safeload.printable(repr(name), 40)} is not a nuScenes "
                                                            f"detection class ({', '.join(detection_names)})")
            score = b.get("detection_score")
            if isinstance(score, bool) or not isinstance(score, (int, float)) or not math.isfinite(score):
                raise _bad(path, f"{where}.detection_score", "must be a finite number")
            if "attribute_name" not in b:
                raise _bad(path, f"{where}.attribute_name", "missing ('' when the box has no attribute)")
            attr = b["attribute_name"]
            if attr != "" and attr not in attribute_names:
                raise _bad(path, f"{where}.attribute_name", f"{safeload.printable(repr(attr), 40)} is not a nuScenes "
                                                            "attribute (or '')")
            if "ego_translation" in b:
                _numbers(b["ego_translation"], 3, path, f"{where}.ego_translation")
            if "num_pts" in b and (isinstance(b["num_pts"], bool) or not isinstance(b["num_pts"], int)):
                raise _bad(path, f"{where}.num_pts", "must be an integer")
    return data


def ground_truth_classes(nusc, sample_tokens, cfg) -> list[str]:
    """The detection classes with a ground-truth box the evaluation keeps (within the class's range, with
    points: the devkit's own loading and filtering), in nuScenes' order."""
    from nuscenes.eval.common.loaders import add_center_dist, filter_eval_boxes, load_gt_of_sample_tokens
    from nuscenes.eval.detection.data_classes import DetectionBox

    with _quiet():
        gt = load_gt_of_sample_tokens(nusc, sample_tokens, DetectionBox, verbose=False)
        if not gt.all:
            return []
        gt = filter_eval_boxes(nusc, add_center_dist(nusc, gt), cfg.class_range, verbose=False)
    have = {b.detection_name for b in gt.all}
    return [n for n in devkit()[3] if n in have]


def _config(classes: list[str]):
    cfg = devkit()[1]("detection_cvpr_2019")
    cfg.class_names = list(classes)       # the classes scored (the devkit averages over class_names)
    return cfg


def evaluate(pred: Path, gt: Path, split: str | None = None, classes: list[str] | str | None = None) -> dict:
    """nuScenes detection metrics of ``pred`` against ``gt`` (see the module docstring).

    Parameters
    ----------
    classes : list of str, ``"all"`` or None
        Detection classes scored; None: those in the ground truth of the split.

    Returns
    -------
    dict
        ``mAP``, ``NDS``, ``tp_errors`` (mATE...), ``per_class`` (AP per threshold, mean AP, TP errors),
        ``classes``, ``split``, ``samples``, ``config`` and the devkit version.
    """
    _, _, DetectionEval, detection_names, _ = devkit()
    nusc, split, tokens = load_ground_truth(gt, split)
    if classes is None:
        classes = ground_truth_classes(nusc, tokens, _config(detection_names))
        if not classes:
            raise UserError(f"{gt}: split {split} has no annotation of a nuScenes detection class within its "
                            "evaluation range")
    elif classes == "all":
        classes = list(detection_names)
    else:
        unknown = [c for c in classes if c not in detection_names]
        if unknown:
            raise UserError(f"--classes: {safeload.printable(unknown[0], 40)} is not a nuScenes detection class "
                            f"({', '.join(detection_names)}, or all)")
    cfg = _config(classes)
    data = read_predictions(pred, tokens, classes, cfg.max_boxes_per_sample)
    n_pred = sum(len(v) for v in data["results"].values())
    with tempfile.TemporaryDirectory(prefix="urbangen-nuscenes-eval-") as tmp:
        if n_pred == 0:   # the devkit cannot filter an empty set: score it as its no_predictions() would
            summary = _no_predictions(classes, cfg)
        else:
            with _quiet():
                ev = DetectionEval(nusc, cfg, str(pred), split, tmp, verbose=False)
                metrics, _ = ev.evaluate()
            summary = metrics.serialize()
    return _result(summary, cfg, classes, split, len(tokens), n_pred)


def _no_predictions(classes, cfg) -> dict:
    return {"mean_ap": 0.0, "nd_score": 0.0, "tp_errors": {k: 1.0 for k in TP_NAMES},
            "label_aps": {c: {str(d): 0.0 for d in cfg.dist_ths} for c in classes},
            "mean_dist_aps": {c: 0.0 for c in classes},
            "label_tp_errors": {c: {k: 1.0 for k in TP_NAMES} for c in classes}}


def _clean(x):
    """JSON-safe copy: NaN (a TP error the devkit leaves undefined) becomes None."""
    if isinstance(x, dict):
        return {str(k): _clean(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_clean(v) for v in x]
    if isinstance(x, float) and not math.isfinite(x):
        return None
    return float(x) if hasattr(x, "__float__") and not isinstance(x, (int, bool)) else x


def _result(summary: dict, cfg, classes, split: str, n_samples: int, n_pred: int) -> dict:
    from importlib.metadata import PackageNotFoundError, version

    try:
        dk = version("nuscenes-devkit")
    except PackageNotFoundError:
        dk = "unknown"
    per_class = {c: {"AP": {str(d): summary["label_aps"][c][str(d)] if str(d) in summary["label_aps"][c]
                            else summary["label_aps"][c][d] for d in cfg.dist_ths},
                     "mean_AP": summary["mean_dist_aps"][c],
                     **{TP_NAMES[k]: summary["label_tp_errors"][c][k] for k in TP_NAMES}} for c in classes}
    return _clean({"metric": "nuScenes detection (nuscenes-devkit DetectionEval)", "devkit": dk, "split": split,
                   "samples": n_samples, "predicted_boxes": n_pred, "classes": list(classes),
                   "mAP": summary["mean_ap"], "NDS": summary["nd_score"],
                   "tp_errors": {TP_NAMES[k]: v for k, v in summary["tp_errors"].items()},
                   "per_class": per_class,
                   "config": {**cfg.serialize(), "class_names": list(classes), "base": "detection_cvpr_2019"}})


def format_result(r: dict) -> str:
    """The devkit's summary as a table: mAP, the TP errors, NDS, then AP per class and threshold."""
    ths = list(next(iter(r["per_class"].values()))["AP"]) if r["per_class"] else []
    fmt = lambda v: "  nan" if v is None else f"{v:.3f}"   # noqa: E731
    errors = "  ".join(f"{k} {fmt(v)}" for k, v in r["tp_errors"].items())
    lines = [f"nuScenes detection, split {r['split']} ({r['samples']} samples, {r['predicted_boxes']} predicted boxes)",
             f"mAP {fmt(r['mAP'])}  NDS {fmt(r['NDS'])}  {errors}",
             f"{'class':<22}" + " ".join(f"AP@{t:<5}" for t in ths) + "  mean   ATE    ASE    AOE    AVE    AAE"]
    for c, v in r["per_class"].items():
        lines.append(f"{c:<22}" + " ".join(f"{fmt(v['AP'][t]):<8}" for t in ths) + f" {fmt(v['mean_AP'])}  "
                     + "  ".join(fmt(v[k]) for k in ("mATE", "mASE", "mAOE", "mAVE", "mAAE")))
    return "\n".join(lines)


def ground_truth_predictions(gt: Path, split: str | None = None) -> dict:
    """The ground truth of a split as a results file (velocity as the devkit derives it, score 1): scored
    against itself it gives mAP 1 and NDS 1 wherever the devkit can derive every velocity."""
    import numpy as np

    nusc, split, tokens = load_ground_truth(gt, split)
    from nuscenes.eval.detection.utils import category_to_detection_name

    attr = {a["token"]: a["name"] for a in nusc.attribute}
    results = {}
    for t in tokens:
        boxes = []
        for a in (nusc.get("sample_annotation", x) for x in nusc.get("sample", t)["anns"]):
            name = category_to_detection_name(a["category_name"])
            if name is None:
                continue
            v = nusc.box_velocity(a["token"])[:2]
            boxes.append({"sample_token": t, "translation": a["translation"], "size": a["size"],
                          "rotation": a["rotation"], "velocity": [float(x) if np.isfinite(x) else 0.0 for x in v],
                          "detection_name": name, "detection_score": 1.0,
                          "attribute_name": attr[a["attribute_tokens"][0]] if a["attribute_tokens"] else ""})
        results[t] = boxes
    return {"meta": {"use_camera": False, "use_lidar": True, "use_radar": False, "use_map": False,
                     "use_external": False}, "results": results}
