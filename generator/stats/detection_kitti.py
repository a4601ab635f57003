"""KITTI 3D object detection AP (R40; 2D, bird's eye view, 3D; easy, moderate, hard), from KITTI's definition.

Written from the object devkit's ``evaluate_object.cpp`` (the R40 version: 41 recall positions,
recall 0 left out of the mean), which no Python library ships on its own:

* per class and difficulty, ground truth is *valid* (type = class), a *neighbour* (Van for Car,
  Person_sitting for Pedestrian: ignored) or another class; a valid box is ignored too when its
  occlusion or truncation exceeds the difficulty's limit or its 2D height is at or below the
  minimum (40 / 25 / 25 px; occlusion 0 / 1 / 2; truncation 0.15 / 0.30 / 0.50). Detections of
  the class lower than the minimum height are ignored; DontCare regions swallow unassigned
  detections that lie mostly inside them (2D metric);
* matching, per image, ground truth in file order: with scores as the recall thresholds, the
  highest-scoring unassigned detection above the class's overlap (Car 0.7, Pedestrian and Cyclist
  0.5; 2D IoU, BEV IoU or 3D IoU, :mod:`generator.stats.box_overlap`); for precision at a
  threshold, the detection of greatest overlap (an ignored one only if nothing else overlaps);
  matches to ignored boxes count neither way;
* thresholds: the scores of true positives, thinned to 41 recall steps (``getThresholds``);
  precision at each, made monotone (max over higher recall), AP = mean of positions 1..40 x 100;
* AOS (2D): orientation similarity ``(1 + cos(alpha_gt - alpha_det)) / 2`` summed over true
  positives, over TP + FP, made monotone and averaged like precision.

The Python evaluations of OpenPCDet and MMDetection3D (ports of the same devkit) give the same
numbers on the same files (``tests/stats/test_detection_kitti.py`` keeps a fixture of theirs).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from generator.stats.box_overlap import bev_iou, box3d_iou, image_iou

METRICS = ("bbox", "bev", "3d")
DIFFICULTIES = ("easy", "moderate", "hard")
MIN_HEIGHT = (40.0, 25.0, 25.0)
MAX_OCCLUSION = (0, 1, 2)
MAX_TRUNCATION = (0.15, 0.30, 0.50)
#: The devkit's overlap per class (KITTI's three) and the usual ones of its neighbours.
MIN_OVERLAP = {"Car": 0.7, "Pedestrian": 0.5, "Cyclist": 0.5, "Van": 0.7, "Person_sitting": 0.5, "Truck": 0.7}
NEIGHBOUR = {"Car": "Van", "Pedestrian": "Person_sitting"}
N_SAMPLE_PTS = 41


@dataclass
class Frame:
    """The objects of one label file as arrays (``score`` zeros for ground truth)."""

    name: np.ndarray          # (n,) str
    truncated: np.ndarray     # (n,)
    occluded: np.ndarray      # (n,) int
    alpha: np.ndarray         # (n,)
    bbox: np.ndarray          # (n, 4)
    dimensions: np.ndarray    # (n, 3) h, w, l
    location: np.ndarray      # (n, 3) bottom centre, camera frame
    rotation_y: np.ndarray    # (n,)
    score: np.ndarray         # (n,)

    @classmethod
    def of(cls, objects) -> Frame:
        """From a list of :class:`generator.formats.kitti_object.KittiObject`."""
        n = len(objects)
        return cls(np.array([o.type for o in objects], dtype=object).reshape(n),
                   np.array([o.truncated for o in objects], np.float64).reshape(n),
                   np.array([o.occluded for o in objects], np.int64).reshape(n),
                   np.array([o.alpha for o in objects], np.float64).reshape(n),
                   np.array([o.bbox for o in objects], np.float64).reshape(n, 4),
                   np.array([o.dimensions for o in objects], np.float64).reshape(n, 3),
                   np.array([o.location for o in objects], np.float64).reshape(n, 3),
                   np.array([o.rotation_y for o in objects], np.float64).reshape(n),
                   np.array([0.0 if o.score is None else o.score for o in objects], np.float64).reshape(n))

    def boxes(self) -> dict:
        return {"location": self.location, "dimensions": self.dimensions, "rotation_y": self.rotation_y}


def clean(gt: Frame, dt: Frame, cls: str, difficulty: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(ignored_gt, ignored_dt, DontCare rows): 0 counted, 1 ignored, -1 another class (see the docstring)."""
    height = gt.bbox[:, 3] - gt.bbox[:, 1]
    valid = np.where(gt.name == cls, 1, np.where(gt.name == NEIGHBOUR.get(cls, "\0"), 0, -1))
    ignore = ((gt.occluded > MAX_OCCLUSION[difficulty]) | (gt.truncated > MAX_TRUNCATION[difficulty])
              | (height <= MIN_HEIGHT[difficulty]))
    ignored_gt = np.where((valid == 1) & ~ignore, 0, np.where((valid == 0) | ((valid == 1) & ignore), 1, -1))
    d_height = np.abs(dt.bbox[:, 3] - dt.bbox[:, 1])
    ignored_dt = np.where(d_height < MIN_HEIGHT[difficulty], 1, np.where(dt.name == cls, 0, -1))
    return ignored_gt.astype(np.int64), ignored_dt.astype(np.int64), np.flatnonzero(gt.name == "DontCare")


@njit(cache=True)
def _statistics(overlap, scores, ignored_gt, ignored_dt, dc_overlap, min_overlap, compute_fp, thresh,
                gt_alpha, dt_alpha, compute_aos):
    """One image: (tp, fp, fn, similarity, tp scores) as ``computeStatistics`` of the devkit.

    ``overlap`` (n_dt, n_gt); ``dc_overlap`` (n_dt, n_dc) over the detection's area (empty: no DontCare).
    """
    n_dt, n_gt = overlap.shape
    no_detection = -10000000.0
    assigned = np.zeros(n_dt, np.bool_)
    below = np.zeros(n_dt, np.bool_)
    if compute_fp:
        for j in range(n_dt):
            below[j] = scores[j] < thresh
    tp, fp, fn = 0, 0, 0
    tp_scores = np.empty(n_gt)
    delta = np.empty(n_gt)
    n_delta = 0
    for i in range(n_gt):
        if ignored_gt[i] == -1:
            continue
        det_idx = -1
        valid_detection = no_detection
        max_overlap = 0.0
        assigned_ignored_det = False
        for j in range(n_dt):
            if ignored_dt[j] == -1 or assigned[j] or below[j]:
                continue
            o = overlap[j, i]
            if not compute_fp and o > min_overlap and scores[j] > valid_detection:
                det_idx = j
                valid_detection = scores[j]
            elif compute_fp and o > min_overlap and (o > max_overlap or assigned_ignored_det) and ignored_dt[j] == 0:
                max_overlap = o
                det_idx = j
                valid_detection = 1.0
                assigned_ignored_det = False
            elif compute_fp and o > min_overlap and valid_detection == no_detection and ignored_dt[j] == 1:
                det_idx = j
                valid_detection = 1.0
                assigned_ignored_det = True
        if valid_detection == no_detection and ignored_gt[i] == 0:
            fn += 1
        elif valid_detection != no_detection and (ignored_gt[i] == 1 or ignored_dt[det_idx] == 1):
            assigned[det_idx] = True
        elif valid_detection != no_detection:
            tp_scores[tp] = scores[det_idx]
            tp += 1
            if compute_aos:
                delta[n_delta] = gt_alpha[i] - dt_alpha[det_idx]
                n_delta += 1
            assigned[det_idx] = True
    similarity = -1.0
    if compute_fp:
        for j in range(n_dt):
            if not (assigned[j] or ignored_dt[j] == -1 or ignored_dt[j] == 1 or below[j]):
                fp += 1
        n_stuff = 0
        for k in range(dc_overlap.shape[1]):
            for j in range(n_dt):
                if assigned[j] or ignored_dt[j] == -1 or ignored_dt[j] == 1 or below[j]:
                    continue
                if dc_overlap[j, k] > min_overlap:
                    assigned[j] = True
                    n_stuff += 1
        fp -= n_stuff
        if compute_aos and (tp > 0 or fp > 0):
            similarity = 0.0
            for k in range(n_delta):
                similarity += (1.0 + np.cos(delta[k])) / 2.0
    return tp, fp, fn, similarity, tp_scores[:tp]


def thresholds(scores: np.ndarray, n_gt: int) -> np.ndarray:
    """The devkit's ``getThresholds``: scores (descending) giving ``N_SAMPLE_PTS`` linearly spaced recalls."""
    v = np.sort(np.asarray(scores, np.float64))[::-1]
    out, current = [], 0.0
    for i in range(len(v)):
        left = (i + 1) / n_gt
        right = (i + 2) / n_gt if i < len(v) - 1 else left
        if (right - current) < (current - left) and i < len(v) - 1:
            continue
        out.append(v[i])
        current += 1.0 / (N_SAMPLE_PTS - 1.0)
    return np.array(out, np.float64)


def _overlaps(gt: Frame, dt: Frame, metric: str) -> np.ndarray:
    if metric == "bbox":
        return image_iou(dt.bbox, gt.bbox)
    return (bev_iou if metric == "bev" else box3d_iou)(dt.boxes(), gt.boxes())


def eval_class(gts: list[Frame], dts: list[Frame], cls: str, difficulty: int, metric: str,
               overlaps: list[np.ndarray], min_overlap: float) -> dict:
    """Precision (and AOS for 2D) at the 41 recall positions of one class, difficulty and metric."""
    aos = metric == "bbox"
    frames = []
    scores, n_gt = [], 0
    for gt, dt, ov in zip(gts, dts, overlaps, strict=True):
        ig, idt, dc = clean(gt, dt, cls, difficulty)
        if metric == "bbox" and len(dc):
            dc_ov = image_iou(dt.bbox, gt.bbox[dc], criterion=0)
        else:
            dc_ov = np.zeros((len(dt.score), 0))
        n_gt += int((ig == 0).sum())
        frames.append((ov, dt.score, ig, idt, dc_ov, gt.alpha, dt.alpha))
        scores.append(_statistics(ov, dt.score, ig, idt, dc_ov, min_overlap, False, 0.0, gt.alpha, dt.alpha, False)[4])
    th = thresholds(np.concatenate(scores) if scores else np.zeros(0), n_gt) if n_gt else np.zeros(0)
    tp, fp, fn, sim = (np.zeros(len(th)) for _ in range(4))
    for ov, sc, ig, idt, dc_ov, ga, da in frames:
        for t, thr in enumerate(th):
            a, b, c, s, _ = _statistics(ov, sc, ig, idt, dc_ov, min_overlap, True, thr, ga, da, aos)
            tp[t] += a
            fp[t] += b
            fn[t] += c
            if s != -1.0:
                sim[t] += s
    precision, orientation = np.zeros(N_SAMPLE_PTS), np.zeros(N_SAMPLE_PTS)
    with np.errstate(divide="ignore", invalid="ignore"):
        precision[:len(th)] = np.nan_to_num(tp / (tp + fp))
        orientation[:len(th)] = np.nan_to_num(sim / (tp + fp))
    for i in range(len(th)):
        precision[i] = precision[i:].max()
        orientation[i] = orientation[i:].max()
    return {"precision": precision, "aos": orientation if aos else None, "n_gt": n_gt}


def ap_r40(precision: np.ndarray) -> float:
    """AP over recall positions 1..40 of 41, in percent (KITTI's R40)."""
    return float(np.sum(precision[1:N_SAMPLE_PTS]) / (N_SAMPLE_PTS - 1) * 100)


def ap_r11(precision: np.ndarray) -> float:
    """AP over every fourth of the 41 positions, in percent (KITTI's older R11)."""
    return float(np.sum(precision[0:N_SAMPLE_PTS:4]) / 11 * 100)


def evaluate(gts: list[Frame], dts: list[Frame], classes=("Car", "Pedestrian", "Cyclist")) -> dict:
    """KITTI AP R40 (and R11) of detections ``dts`` against ground truth ``gts`` (one Frame per image, same order).

    Returns
    -------
    dict
        ``{class: {"min_overlap", "n_gt", "AP_R40": {metric: [easy, moderate, hard]}, "AP_R11": {...},
        "AOS_R40": [...]}}`` in percent; metrics ``bbox``, ``bev``, ``3d``.
    """
    out = {}
    cache = {m: [_overlaps(g, d, m) for g, d in zip(gts, dts, strict=True)] for m in METRICS}
    for cls in classes:
        mo = MIN_OVERLAP[cls]
        res = {"min_overlap": mo, "AP_R40": {}, "AP_R11": {}, "AOS_R40": None, "n_gt": []}
        for metric in METRICS:
            r40, r11 = [], []
            for d in range(3):
                e = eval_class(gts, dts, cls, d, metric, cache[metric], mo)
                r40.append(ap_r40(e["precision"]))
                r11.append(ap_r11(e["precision"]))
                if metric == "bbox":
                    res["n_gt"].append(e["n_gt"])
                    res.setdefault("_aos", []).append(ap_r40(e["aos"]))
            res["AP_R40"][metric], res["AP_R11"][metric] = r40, r11
        res["AOS_R40"] = res.pop("_aos")
        out[cls] = res
    return out


def format_result(result: dict) -> str:
    """The table the devkit prints: per class, AP R40 of bbox, bev, 3d and AOS at easy, moderate, hard."""
    lines = []
    for cls, r in result.items():
        lines.append(f"{cls} AP_R40@{r['min_overlap']:.2f} (easy, moderate, hard; ground truth {r['n_gt']}):")
        for m in METRICS:
            lines.append(f"  {m:<4} " + ", ".join(f"{v:.4f}" for v in r["AP_R40"][m]))
        lines.append("  aos  " + ", ".join(f"{v:.4f}" for v in r["AOS_R40"]))
    return "\n".join(lines)
