"""IoU / mIoU of semantic labels (seed 000 Eq. 11-12), computed as the SemanticKITTI reference does.

``IoU_c = TP_c / (TP_c + FP_c + FN_c)`` and ``mIoU = (1/C) sum_c IoU_c``.

Conventions (semantic-kitti-api ``auxiliary/np_ioueval.py`` ``iouEval`` and
``evaluate_semantics.py``):

* the confusion matrix is indexed ``[prediction, ground truth]`` and built with one
  ``np.bincount`` per scan (streaming: one scan in memory at a time);
* class 0 (unlabeled) is ignored *as ground truth only*: its column is zeroed, so points
  labelled 0 count nowhere, but a labelled point predicted 0 is a false negative of its
  class (6 building points, one predicted 0: IoU 5/6);
* the mean runs over every class of the label set but 0 (``mean_over="all"``): a class
  absent from both prediction and ground truth counts as IoU 0, as the reference's
  ``1e-15`` in the union makes it. ``mean_over="present"`` leaves such classes out instead;
* accuracy is the reference's: TP / (TP + FP) over the non-ignored classes (points
  predicted 0 are in neither).

Label sets (:data:`LABEL_SETS`): ``unified11`` (seed 000's 11 classes, from the raw ids),
``semantickitti`` (the 19 learning classes of the SemanticKITTI benchmark via the
``learning_map`` of the label config), ``native`` (urbangen's native classes, read from the
``native_labels/`` side files, which both trees must have). Predictions are read from
``sequences/NN/predictions/`` (the reference's layout) when that folder exists, else from
``labels/``. With ``panoptic=True`` the same pass feeds :mod:`generator.stats.panoptic`.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generator.errors import UserError
from generator.formats import semantickitti as sk
from generator.formats.point_sidecars import NATIVE_DIR, read_sidecar
from generator.labels.sets import LABEL_SET_NAMES as LABEL_SETS
from generator.labels.sets import LabelSet, label_sets
from generator.progress import progress as progress_bar
from generator.stats.panoptic import MIN_POINTS, PanopticAccumulator, panoptic_result

IGNORE = 0
#: Which classes the means average: every non-ignored class (the reference) or those present.
MEAN_OVER = ("all", "present")
PREDICTIONS_DIR = "predictions"


def confusion(pred: np.ndarray, gt: np.ndarray, n_classes: int) -> np.ndarray:
    """(n, n) int64 confusion matrix ``[pred, gt]`` of two (m,) integer label arrays in ``0..n-1``."""
    pred = np.asarray(pred, np.int64)
    gt = np.asarray(gt, np.int64)
    if gt.shape != pred.shape:
        raise ValueError(f"{gt.shape} ground-truth labels but {pred.shape} predictions")
    return np.bincount(pred * n_classes + gt, minlength=n_classes * n_classes).reshape(n_classes, n_classes)


@dataclass
class IoUResult:
    """Per-class IoU of a confusion matrix.

    Attributes
    ----------
    iou : (n,) float64
        IoU per class; NaN for ignored classes and classes absent from both sides.
    tp, fp, fn : (n,) int64
    present : (n,) bool
        Not ignored and in prediction or ground truth (TP + FP + FN > 0).
    evaluated : (n,) bool
        Classes in the mean (all non-ignored ones, or only the present ones).
    miou : float
        Mean IoU over ``evaluated``, absent classes counting 0 (NaN when none).
    accuracy : float
        TP / (TP + FP) summed over the non-ignored classes.
    """

    iou: np.ndarray
    tp: np.ndarray
    fp: np.ndarray
    fn: np.ndarray
    present: np.ndarray
    evaluated: np.ndarray
    miou: float
    accuracy: float


def iou_from_confusion(conf: np.ndarray, ignore: tuple[int, ...] = (IGNORE,), mean_over: str = "present") -> IoUResult:
    """Seed 000 Eq. 11-12 on a ``[pred, gt]`` confusion matrix (see the module conventions).

    Parameters
    ----------
    conf : (n, n) int
        ``[pred, gt]`` counts.
    ignore : tuple of int
        Classes ignored as ground truth (their columns are zeroed).
    mean_over : {"all", "present"}
        ``"all"`` is the reference; ``"present"`` (the default here, for symmetric uses such
        as camera-LiDAR agreement with nothing ignored) leaves absent classes out of the mean.
    """
    if mean_over not in MEAN_OVER:
        raise ValueError(f"mean_over must be one of {MEAN_OVER}, got {mean_over!r}")
    c = np.array(conf, np.int64, copy=True)
    ign = list(ignore)
    c[:, ign] = 0
    tp = np.diag(c).copy()
    fp = c.sum(1) - tp
    fn = c.sum(0) - tp
    union = tp + fp + fn
    include = np.ones(len(c), bool)
    include[ign] = False
    present = (union > 0) & include
    iou = np.full(len(c), np.nan)
    iou[present] = tp[present] / union[present]
    evaluated = include if mean_over == "all" else present
    miou = float(np.nan_to_num(iou[evaluated], nan=0.0).mean()) if evaluated.any() else float("nan")
    denom = tp[include].sum() + fp[include].sum()
    return IoUResult(
        iou, tp, fp, fn, present, evaluated, miou, float(tp[include].sum() / denom) if denom else float("nan")
    )


def _read_native(seq: Path, index: int, raw: np.ndarray) -> np.ndarray:
    native = read_sidecar(seq, NATIVE_DIR, index, len(raw))
    if native is None:
        raise UserError(
            f"{seq / NATIVE_DIR}: no native labels for scan {index:06d} (use --labels unified11 or semantickitti)"
        )
    return native.astype(np.int64)


def read_ids(ls: LabelSet, seq: Path, index: int, raw: np.ndarray, source: str | Path = "labels") -> np.ndarray:
    """(n,) int64 ids in label set ``ls`` of scan ``index``: from its raw ids, or its native side file.

    Raises
    ------
    UserError
        A raw id the SemanticKITTI label table does not know (``source`` names the file), or a
        native side file that is missing or holds ids outside the class table.
    """
    if ls.from_raw is None:
        return _read_native(seq, index, raw)
    sk.check_raw_ids(raw, source)
    return ls.from_raw[raw]


def prediction_path(pred_dir: Path, index: int) -> Path:
    """The prediction file of scan ``index``: ``predictions/`` (reference layout) if present, else ``labels/``."""
    sub = PREDICTIONS_DIR if (pred_dir / PREDICTIONS_DIR).is_dir() else "labels"
    return pred_dir / sub / f"{index:06d}.label"


def _pairs(pred_root: Path, gt_root: Path, sequences: list[str] | None) -> Iterator[tuple[Path, Path, int]]:
    gt_seqs = sk.list_sequences(gt_root)
    pred_seqs = set(sk.list_sequences(pred_root))
    for name in sequences or gt_seqs:
        if name not in gt_seqs:
            raise UserError(f"{gt_root / 'sequences' / name}: no such ground-truth sequence")
        if name not in pred_seqs:
            raise UserError(f"{pred_root / 'sequences' / name}: missing (ground truth has sequence {name})")
        gt_dir, pred_dir = sk.sequence_dir(gt_root, name), sk.sequence_dir(pred_root, name)
        stems = sorted(int(p.stem) for p in (gt_dir / "labels").glob("*.label") if p.stem.isdigit())
        if not stems:
            raise UserError(f"{gt_dir / 'labels'}: no .label files")
        for i in stems:
            yield gt_dir, pred_dir, i


def evaluate_trees(pred_root: str | Path, gt_root: str | Path, labels: str = "unified11",
                   sequences: list[str] | None = None, progress: bool = True, mean_over: str = "all",
                   panoptic: bool = False, min_points: int = MIN_POINTS) -> dict:
    """Stream every scan of two SemanticKITTI-layout label trees into one confusion matrix.

    Parameters
    ----------
    pred_root, gt_root : path-like
        Dataset roots (``sequences/NN/labels/NNNNNN.label``; predictions may sit in
        ``predictions/`` instead); every ground-truth scan must have a prediction with as many points.
    labels : str
        One of :data:`LABEL_SETS`.
    sequences : list of str, optional
        Sequence names (default: every ground-truth sequence).
    mean_over : {"all", "present"}
        Classes the means average (default: all non-ignored ones, as the reference).
    panoptic : bool
        Also compute PQ / SQ / RQ (:mod:`generator.stats.panoptic`) under ``"panoptic"``.
    min_points : int
        Panoptic: unmatched segments smaller than this count neither as FP nor FN.

    Returns
    -------
    dict
        JSON-able result: label set, classes with IoU / TP / FP / FN, mIoU, the absent
        classes, accuracy, point and scan counts, the confusion matrix ``[pred, gt]``.
    """
    sets = label_sets()
    if labels not in sets:
        raise UserError(f"--labels: must be one of {', '.join(LABEL_SETS)}, got {labels!r}")
    if mean_over not in MEAN_OVER:
        raise UserError(f"--mean-over: must be one of {', '.join(MEAN_OVER)}, got {mean_over!r}")
    if min_points < 1:
        raise UserError(f"--min-points: must be >= 1, got {min_points}")
    ls = sets[labels]
    n = len(ls.names)
    conf = np.zeros((n, n), np.int64)
    pan = PanopticAccumulator(n, (IGNORE,), min_points) if panoptic else None
    pairs = list(_pairs(Path(pred_root), Path(gt_root), sequences))
    for gt_dir, pred_dir, i in progress_bar(pairs, desc=f"eval {labels}", unit="scan", enabled=progress):
        gt_raw, gt_inst = sk.read_labels(gt_dir / "labels" / f"{i:06d}.label")
        pred_path = prediction_path(pred_dir, i)
        if not os.path.lexists(pred_path):
            raise UserError(f"{pred_path}: missing prediction (ground truth has {gt_dir.name}/{i:06d})")
        pred_raw, pred_inst = sk.read_labels(pred_path)
        if len(pred_raw) != len(gt_raw):
            raise UserError(f"{pred_path}: {len(pred_raw)} labels but the ground truth has {len(gt_raw)} points")
        gt_ids = read_ids(ls, gt_dir, i, gt_raw, gt_dir / "labels" / f"{i:06d}.label")
        pred_ids = read_ids(ls, pred_dir, i, pred_raw, pred_path)
        conf += confusion(pred_ids, gt_ids, n)
        if pan is not None:
            pan.add(pred_ids, sk.encode_labels(pred_raw, pred_inst), gt_ids, sk.encode_labels(gt_raw, gt_inst))
    res = iou_from_confusion(conf, mean_over=mean_over)
    out = result_dict(ls, res, conf, scans=len(pairs), mean_over=mean_over)
    if pan is not None:
        out["panoptic"] = panoptic_result(pan, ls, res.iou, mean_over)
    return out


def result_dict(ls: LabelSet, res: IoUResult, conf: np.ndarray, scans: int, mean_over: str = "all") -> dict:
    """The JSON record of an evaluation."""
    classes = []
    for c, name in enumerate(ls.names):
        status = "ignored" if c == IGNORE else ("present" if res.present[c] else "absent")
        classes.append({"id": c, "name": name, "iou": None if np.isnan(res.iou[c]) else float(res.iou[c]),
                        "tp": int(res.tp[c]), "fp": int(res.fp[c]), "fn": int(res.fn[c]),
                        "status": status, "in_mean": bool(res.evaluated[c])})
    absent = [ls.names[c] for c in range(len(ls.names)) if c != IGNORE and not res.present[c]]
    return {
        "labels": ls.name,
        "formula": "IoU_c = TP/(TP+FP+FN) from confusion[pred, gt] with only the ground-truth ignore column zeroed; "
                   + ("mIoU = mean over every non-ignored class, absent ones as 0 (semantic-kitti-api)"
                      if mean_over == "all" else "mIoU = mean over the classes present in prediction or ground truth"),
        "mean_over": mean_over,
        "ignored": [ls.names[IGNORE]],
        "miou": None if np.isnan(res.miou) else res.miou,
        "accuracy": None if np.isnan(res.accuracy) else res.accuracy,
        "evaluated_classes": int(res.evaluated.sum()),
        "absent_classes": absent,
        "scans": scans,
        "points": int(conf.sum()),
        "points_evaluated": int(conf[:, [c for c in range(len(conf)) if c != IGNORE]].sum()),
        "classes": classes,
        "confusion_pred_gt": conf.tolist(),
    }


def format_table(result: dict) -> str:
    """A plain-text table of a :func:`evaluate_trees` result (one line per class in the mean, then mIoU)."""
    lines = [f"{'class':<16} {'IoU %':>8} {'TP':>10} {'FP':>10} {'FN':>10}"]
    for c in result["classes"]:
        if c["in_mean"]:
            iou = "absent" if c["iou"] is None else f"{100 * c['iou']:8.2f}"
            lines.append(f"{c['name']:<16} {iou:>8} {c['tp']:10d} {c['fp']:10d} {c['fn']:10d}")
    miou = result["miou"]
    lines.append(
        f"{'mIoU':<16} {'n/a' if miou is None else f'{100 * miou:8.2f}':>8}  over {result['evaluated_classes']} classes"
    )
    if result["absent_classes"]:
        how = "counted as IoU 0 in the mean, as semantic-kitti-api does" if result["mean_over"] == "all" \
            else "left out of the mean: --mean-over present"
        lines.append(f"absent from prediction and ground truth ({how}): {', '.join(result['absent_classes'])}")
    acc = result["accuracy"]
    lines.append(f"accuracy {'n/a' if acc is None else f'{100 * acc:.2f}'} %; ignored as ground truth: "
                 f"{', '.join(result['ignored'])}; {result['points_evaluated']} of {result['points']} points "
                 f"evaluated, {result['scans']} scans")
    return "\n".join(lines)
