"""IoU / mIoU of semantic labels (seed 000 Eq. 11-12) with SemanticKITTI conventions.

``IoU_c = TP_c / (TP_c + FP_c + FN_c)`` and ``mIoU = (1/C) sum_c IoU_c``.

Conventions (as the SemanticKITTI API's ``iouEval``):

* the confusion matrix is indexed ``[ground truth, prediction]`` and built with one
  ``np.bincount`` per scan (streaming: one scan in memory at a time);
* class 0 (unlabeled) is ignored: its row AND column are zeroed before the statistics, so
  ground-truth-unlabeled points count nowhere and predictions of 0 are neither TP nor FP;
* unlike the SemanticKITTI API, classes absent from both prediction and ground truth
  (TP + FP + FN = 0) have no IoU and are left out of the mean; the result lists them.

Label sets (:data:`LABEL_SETS`): ``unified11`` (seed 000's 11 classes, from the raw ids),
``semantickitti`` (the 19 learning classes of the SemanticKITTI benchmark via the
``learning_map`` of the label config), ``native`` (urbangen's native classes, read from the
``native_labels/`` side files, which both trees must have).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Iterator

import numpy as np
from tqdm import tqdm

from generator.errors import UserError
from generator.formats import semantickitti as sk
from generator.formats.point_sidecars import NATIVE_DIR, read_sidecar
from generator.labels.sets import LABEL_SET_NAMES as LABEL_SETS, LabelSet, label_sets

IGNORE = 0


def confusion(gt: np.ndarray, pred: np.ndarray, n_classes: int) -> np.ndarray:
    """(n, n) int64 confusion matrix ``[gt, pred]`` of two (m,) integer label arrays in ``0..n-1``."""
    gt = np.asarray(gt, np.int64)
    pred = np.asarray(pred, np.int64)
    if gt.shape != pred.shape:
        raise ValueError(f"{gt.shape} ground-truth labels but {pred.shape} predictions")
    return np.bincount(gt * n_classes + pred, minlength=n_classes * n_classes).reshape(n_classes, n_classes)


@dataclass
class IoUResult:
    """Per-class IoU of a confusion matrix.

    Attributes
    ----------
    iou : (n,) float64
        IoU per class; NaN for the ignored class and classes absent from both sides.
    tp, fp, fn : (n,) int64
    evaluated : (n,) bool
        Classes in the mean (not ignored, present in prediction or ground truth).
    miou : float
        Mean IoU over ``evaluated`` (NaN when none).
    accuracy : float
        TP sum over all counted points (after ignoring).
    """

    iou: np.ndarray
    tp: np.ndarray
    fp: np.ndarray
    fn: np.ndarray
    evaluated: np.ndarray
    miou: float
    accuracy: float


def iou_from_confusion(conf: np.ndarray, ignore: tuple[int, ...] = (IGNORE,)) -> IoUResult:
    """Seed 000 Eq. 11-12 on a ``[gt, pred]`` confusion matrix (see the module conventions)."""
    c = np.array(conf, np.int64, copy=True)
    ign = list(ignore)
    c[ign, :] = 0
    c[:, ign] = 0
    tp = np.diag(c).copy()
    fn = c.sum(1) - tp
    fp = c.sum(0) - tp
    union = tp + fp + fn
    evaluated = union > 0
    evaluated[ign] = False
    iou = np.full(len(c), np.nan)
    iou[evaluated] = tp[evaluated] / union[evaluated]
    miou = float(iou[evaluated].mean()) if evaluated.any() else float("nan")
    total = c.sum()
    return IoUResult(iou, tp, fp, fn, evaluated, miou, float(tp.sum() / total) if total else float("nan"))


def _read_native(seq: Path, index: int, raw: np.ndarray) -> np.ndarray:
    native = read_sidecar(seq, NATIVE_DIR, index, len(raw))
    if native is None:
        raise UserError(f"{seq / NATIVE_DIR}: no native labels for scan {index:06d} (use --labels unified11 or semantickitti)")
    return native.astype(np.int64)


def read_ids(ls: LabelSet, seq: Path, index: int, raw: np.ndarray) -> np.ndarray:
    """(n,) int64 ids in label set ``ls`` of scan ``index``: from its raw ids, or its native side file."""
    return _read_native(seq, index, raw) if ls.from_raw is None else ls.from_raw[raw]


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
                   sequences: list[str] | None = None, progress: bool = True) -> dict:
    """Stream every scan of two SemanticKITTI-layout label trees into one confusion matrix.

    Parameters
    ----------
    pred_root, gt_root : path-like
        Dataset roots (``sequences/NN/labels/NNNNNN.label``); every ground-truth scan must
        have a prediction with as many points.
    labels : str
        One of :data:`LABEL_SETS`.
    sequences : list of str, optional
        Sequence names (default: every ground-truth sequence).

    Returns
    -------
    dict
        JSON-able result: label set, classes with IoU / TP / FP / FN, mIoU, the classes left
        out of the mean, accuracy, point and scan counts, the confusion matrix ``[gt, pred]``.
    """
    sets = label_sets()
    if labels not in sets:
        raise UserError(f"--labels: must be one of {', '.join(LABEL_SETS)}, got {labels!r}")
    ls = sets[labels]
    n = len(ls.names)
    conf = np.zeros((n, n), np.int64)
    pairs = list(_pairs(Path(pred_root), Path(gt_root), sequences))
    for gt_dir, pred_dir, i in tqdm(pairs, desc=f"eval {labels}", unit="scan", disable=None if progress else True):
        gt_raw, _ = sk.read_labels(gt_dir / "labels" / f"{i:06d}.label")
        pred_path = pred_dir / "labels" / f"{i:06d}.label"
        if not pred_path.is_file():
            raise UserError(f"{pred_path}: missing prediction (ground truth has {gt_dir.name}/{i:06d})")
        pred_raw, _ = sk.read_labels(pred_path)
        if len(pred_raw) != len(gt_raw):
            raise UserError(f"{pred_path}: {len(pred_raw)} labels but the ground truth has {len(gt_raw)} points")
        conf += confusion(read_ids(ls, gt_dir, i, gt_raw), read_ids(ls, pred_dir, i, pred_raw), n)
    res = iou_from_confusion(conf)
    return result_dict(ls, res, conf, scans=len(pairs))


def result_dict(ls: LabelSet, res: IoUResult, conf: np.ndarray, scans: int) -> dict:
    """The JSON record of an evaluation."""
    classes = []
    for c, name in enumerate(ls.names):
        classes.append({"id": c, "name": name, "iou": None if np.isnan(res.iou[c]) else float(res.iou[c]),
                        "tp": int(res.tp[c]), "fp": int(res.fp[c]), "fn": int(res.fn[c]),
                        "status": "ignored" if c == IGNORE else ("evaluated" if res.evaluated[c] else "absent")})
    return {
        "labels": ls.name,
        "formula": "IoU_c = TP/(TP+FP+FN); mIoU = mean over evaluated classes (seed 000 Eq. 11-12)",
        "ignored": [ls.names[IGNORE]],
        "miou": None if np.isnan(res.miou) else res.miou,
        "accuracy": None if np.isnan(res.accuracy) else res.accuracy,
        "evaluated_classes": int(res.evaluated.sum()),
        "absent_classes": [ls.names[c] for c in range(len(ls.names)) if c != IGNORE and not res.evaluated[c]],
        "scans": scans,
        "points": int(conf.sum()),
        "points_evaluated": int(res.tp.sum() + res.fn.sum()),
        "classes": classes,
        "confusion_gt_pred": conf.tolist(),
    }


def format_table(result: dict) -> str:
    """A plain-text table of a :func:`evaluate_trees` result (one line per class, then mIoU)."""
    lines = [f"{'class':<16} {'IoU %':>8} {'TP':>10} {'FP':>10} {'FN':>10}"]
    for c in result["classes"]:
        if c["status"] == "evaluated":
            lines.append(f"{c['name']:<16} {100 * c['iou']:8.2f} {c['tp']:10d} {c['fp']:10d} {c['fn']:10d}")
    miou = result["miou"]
    lines.append(f"{'mIoU':<16} {'n/a' if miou is None else f'{100 * miou:8.2f}':>8}  over {result['evaluated_classes']} classes")
    if result["absent_classes"]:
        lines.append(f"left out of the mean (absent from prediction and ground truth): {', '.join(result['absent_classes'])}")
    lines.append(f"ignored: {', '.join(result['ignored'])}; {result['points_evaluated']} of {result['points']} points "
                 f"evaluated, {result['scans']} scans")
    return "\n".join(lines)
