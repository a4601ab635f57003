"""Panoptic quality (PQ, SQ, RQ) of LiDAR labels, as SemanticKITTI's panoptic benchmark defines it.

Definition (semantic-kitti-api ``auxiliary/eval_np.py`` ``PanopticEval`` and
``evaluate_panoptic.py``), per scan and per class ``c`` (every class of the label set but
the ignored class 0):

* points whose ground-truth class is ignored (0) are dropped, whatever their prediction;
* a *segment* of class ``c`` is the set of points of class ``c`` sharing one full
  ``.label`` value (raw id | instance << 16). Things (instance ids > 0) give one segment per
  object; stuff (instance 0) one segment per raw id in the scan;
* a ground-truth and a predicted segment of class ``c`` match when their IoU is > 0.5
  (then the match is unique): TP, and the IoU is added to the class's IoU sum;
* an unmatched ground-truth segment of at least ``min_points`` points is a FN, an
  unmatched predicted segment of at least ``min_points`` points a FP (smaller ones count
  nowhere; the reference default is 50);
* over all scans: ``SQ_c = IoU sum / TP``, ``RQ_c = TP / (TP + FP/2 + FN/2)``,
  ``PQ_c = SQ_c RQ_c`` (0 where the denominators are 0), and PQ, SQ, RQ are means over the
  classes (by default all non-ignored classes, absent ones counting 0, as the reference).

``PQ_things`` and ``PQ_stuff`` average the thing and stuff classes (:func:`thing_classes`),
``PQ_dagger`` (PQ†) averages PQ over things and IoU over stuff.
"""

from __future__ import annotations

import numpy as np

from generator.labels import class_table
from generator.labels.sets import LabelSet

#: SemanticKITTI's thing classes (semantic-kitti-api ``evaluate_panoptic.py``), the learning classes 1-8.
SEMANTICKITTI_THINGS = ("car", "truck", "bicycle", "motorcycle", "other-vehicle", "person", "bicyclist", "motorcyclist")
MIN_POINTS = 50
EPS = 1e-15


def thing_classes(ls: LabelSet) -> np.ndarray:
    """(n,) bool: the thing classes of label set ``ls``.

    SemanticKITTI's own list for the ``semantickitti`` set; for the others, the classes a
    native class with the ``thing`` flag of ``classes.yaml`` maps to.
    """
    if ls.name == "semantickitti":
        return np.array([n in SEMANTICKITTI_THINGS for n in ls.names])
    out = np.zeros(len(ls.names), bool)
    flags = np.array([r.thing for r in class_table().rows])
    out[ls.from_native[flags]] = True
    out[0] = False
    return out


def _index(ids: np.ndarray, values: np.ndarray) -> np.ndarray:
    return np.searchsorted(ids, values)


class PanopticAccumulator:
    """Streams scans into per-class panoptic counts.

    Parameters
    ----------
    n_classes : int
    ignore : tuple of int
        Ignored classes (points with such a ground-truth class are dropped).
    min_points : int
        Unmatched segments smaller than this are neither FP nor FN.
    """

    def __init__(self, n_classes: int, ignore: tuple[int, ...] = (0,), min_points: int = MIN_POINTS):
        self.n = n_classes
        self.ignore = tuple(ignore)
        self.include = np.array([c for c in range(n_classes) if c not in self.ignore], np.int64)
        self.min_points = int(min_points)
        self.tp = np.zeros(n_classes, np.int64)
        self.fp = np.zeros(n_classes, np.int64)
        self.fn = np.zeros(n_classes, np.int64)
        self.iou_sum = np.zeros(n_classes, np.float64)

    def add(
        self, pred_class: np.ndarray, pred_segment: np.ndarray, gt_class: np.ndarray, gt_segment: np.ndarray
    ) -> None:
        """Add one scan.

        Parameters
        ----------
        pred_class, gt_class : (m,) int
            Class ids in the label set.
        pred_segment, gt_segment : (m,) uint32 or int64
            Segment ids (the full ``.label`` values); compared only within one class.
        """
        keep = ~np.isin(gt_class, self.ignore)
        pc, ps = np.asarray(pred_class)[keep], np.asarray(pred_segment, np.int64)[keep]
        gc, gs = np.asarray(gt_class)[keep], np.asarray(gt_segment, np.int64)[keep]
        for c in np.intersect1d(self.include, np.union1d(np.unique(pc), np.unique(gc))):
            pm, gm = pc == c, gc == c
            p_ids, p_area = np.unique(ps[pm], return_counts=True)
            g_ids, g_area = np.unique(gs[gm], return_counts=True)
            both = pm & gm
            pairs, inter = np.unique(np.stack([gs[both], ps[both]]), axis=1, return_counts=True)
            gi, pi = _index(g_ids, pairs[0]), _index(p_ids, pairs[1])
            iou = inter / (g_area[gi] + p_area[pi] - inter)
            match = iou > 0.5
            self.tp[c] += int(match.sum())
            self.iou_sum[c] += float(iou[match].sum())
            g_matched = np.zeros(len(g_ids), bool)
            p_matched = np.zeros(len(p_ids), bool)
            g_matched[gi[match]] = True
            p_matched[pi[match]] = True
            self.fn[c] += int(((g_area >= self.min_points) & ~g_matched).sum())
            self.fp[c] += int(((p_area >= self.min_points) & ~p_matched).sum())

    def scores(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(pq, sq, rq), each (n,) float64 per class (0 where undefined, as the reference)."""
        sq = self.iou_sum / np.maximum(self.tp, EPS)
        rq = self.tp / np.maximum(self.tp + 0.5 * self.fp + 0.5 * self.fn, EPS)
        return sq * rq, sq, rq

    def present(self) -> np.ndarray:
        """(n,) bool: non-ignored classes with a segment on either side (TP + FP + FN > 0)."""
        out = (self.tp + self.fp + self.fn) > 0
        out[list(self.ignore)] = False
        return out


def panoptic_result(acc: PanopticAccumulator, ls: LabelSet, iou: np.ndarray, mean_over: str = "all") -> dict:
    """The JSON record of a panoptic evaluation.

    Parameters
    ----------
    acc : PanopticAccumulator
    ls : LabelSet
    iou : (n,) float64
        Semantic IoU per class (NaN for absent classes: counted as 0 as the reference does).
    mean_over : {"all", "present"}
        Average over every non-ignored class (reference) or only the classes with segments.
    """
    pq, sq, rq = acc.scores()
    iou0 = np.nan_to_num(iou, nan=0.0)
    things = thing_classes(ls)
    inc = np.zeros(acc.n, bool)
    inc[acc.include] = True
    mean_set = inc if mean_over == "all" else acc.present()

    def mean(values: np.ndarray, mask: np.ndarray) -> float | None:
        return float(values[mask].mean()) if mask.any() else None

    classes = [{"id": int(c), "name": ls.names[c], "thing": bool(things[c]), "pq": float(pq[c]), "sq": float(sq[c]),
                "rq": float(rq[c]), "iou": float(iou0[c]), "tp": int(acc.tp[c]), "fp": int(acc.fp[c]),
                "fn": int(acc.fn[c]), "in_mean": bool(mean_set[c])}
               for c in acc.include]
    dagger = np.where(things, pq, iou0)
    return {
        "definition": "SemanticKITTI panoptic (semantic-kitti-api eval_np.PanopticEval): segments = full label "
                      "values per class, match IoU > 0.5, unmatched segments under min_points ignored, class 0 ignored",
        "min_points": acc.min_points,
        "mean_over": mean_over,
        "pq": mean(pq, mean_set), "sq": mean(sq, mean_set), "rq": mean(rq, mean_set),
        "pq_things": mean(pq, mean_set & things), "pq_stuff": mean(pq, mean_set & ~things),
        "pq_dagger": mean(dagger, mean_set),
        "classes": classes,
    }


def format_panoptic(result: dict) -> str:
    """Plain-text table of :func:`panoptic_result` (one line per class in the mean, then the means)."""
    lines = [f"{'class':<16} {'kind':<6} {'PQ %':>7} {'SQ %':>7} {'RQ %':>7} {'TP':>7} {'FP':>7} {'FN':>7}"]
    for c in result["classes"]:
        if c["in_mean"]:
            lines.append(f"{c['name']:<16} {'thing' if c['thing'] else 'stuff':<6} {100 * c['pq']:7.2f} "
                         f"{100 * c['sq']:7.2f} {100 * c['rq']:7.2f} {c['tp']:7d} {c['fp']:7d} {c['fn']:7d}")

    def pct(v):
        return "n/a" if v is None else f"{100 * v:.2f}"

    lines.append(
        f"PQ {pct(result['pq'])}  SQ {pct(result['sq'])}  RQ {pct(result['rq'])}  "
        f"PQ_things {pct(result['pq_things'])}  PQ_stuff {pct(result['pq_stuff'])}  PQ† {pct(result['pq_dagger'])}"
        f"  (min {result['min_points']} points per unmatched segment)"
    )
    return "\n".join(lines)
