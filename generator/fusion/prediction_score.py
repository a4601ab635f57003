"""Predicted labels on the points of a scan, and their scores against the LiDAR ground truth.

Fusing (:func:`fuse_scan`): a point seen by several images of its scan (the weather x time variants of a
frame, the ``image_2`` of the KITTI stream) takes the label most of them predict at its pixel (ties: the
lower id); with the occlusion test ``on`` only images in which the point passes it vote, ``off`` every
image it falls into (seed 001, which had no test). A point no image labels has none (-1).

Scoring (:class:`PredictionScore`): per label set the prediction determines
(:func:`generator.labels.class_sets.compatible_sets`) and per variant -- occlusion ``on``/``off`` x
exclusions ``included``/``excluded`` (points on a 1-px boundary of the rendered labels, or of a hull-proxy
class in the LiDAR truth or the rendered image, as in :mod:`generator.fusion.agreement`) -- one confusion
matrix ``[prediction, ground truth]`` over the labelled ("fused") points, scored with
semantic-kitti-api's conventions (:func:`generator.stats.evaluate.iou_from_confusion`: the set's ignored
classes ignored as ground truth only, mean over every other class with absent ones as 0; the mean over
the present classes beside it). The semantic maps are scored voxel by voxel the same way
(:func:`score_maps`): each voxel's majority predicted label against its majority true label, over the
voxels of the labelled points.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from generator.fusion.prediction_views import ViewLabels
from generator.labels import class_table
from generator.labels.class_sets import ClassSet
from generator.stats.evaluate import iou_from_confusion

OCCLUSION = ("on", "off")
EXCLUSIONS = ("excluded", "included")
VARIANTS = list(itertools.product(OCCLUSION, EXCLUSIONS))
#: The variant the headline figure refers to (as ``fuse``'s agreement headline).
HEADLINE = ("on", "excluded")


def variant_key(v: tuple[str, str]) -> str:
    return f"occlusion={v[0]},boundaries_and_proxies={v[1]}"


def vote(n: int, index: np.ndarray, labels: np.ndarray) -> np.ndarray:
    """(n,) int64 majority label per point of ``(index, label)`` votes; -1 where there is none; ties: lower label."""
    out = np.full(n, -1, np.int64)
    if not len(index):
        return out
    pairs, count = np.unique(np.stack([index, labels], -1), axis=0, return_counts=True)
    order = np.lexsort((pairs[:, 1], -count, pairs[:, 0]))  # per point: most votes first, then lower label
    first = np.r_[True, pairs[order][1:, 0] != pairs[order][:-1, 0]]
    best = pairs[order][first]
    out[best[:, 0]] = best[:, 1]
    return out


@dataclass
class ScanFusion:
    """Predicted labels of one scan's points.

    Attributes
    ----------
    label : dict of str -> (n,) int64
        Occlusion ``on`` / ``off`` -> predicted id per point (-1: no image labels it).
    excluded : dict of str -> (n,) bool
        Points the ``excluded`` variants leave out (boundary or hull-proxy pixel in a voting image,
        or a hull-proxy LiDAR class).
    views : int
        Images that labelled the scan.
    """

    label: dict
    excluded: dict
    views: int


def fuse_scan(n: int, native: np.ndarray, views: list[ViewLabels]) -> ScanFusion:
    """Combine the views of one scan of ``n`` points with LiDAR truth ``native`` (n,) (see the module docstring)."""
    hull = class_table().hull_classes
    label, excluded = {}, {}
    for occ in OCCLUSION:
        parts = [(v.index[v.visible], v.pred[v.visible], (v.boundary | hull[v.image_class])[v.visible])
                 if occ == "on" else (v.index, v.pred, v.boundary | hull[v.image_class]) for v in views]
        idx = np.concatenate([p[0] for p in parts]) if parts else np.zeros(0, np.int64)
        label[occ] = vote(n, idx, np.concatenate([p[1] for p in parts]) if parts else idx)
        flag = np.zeros(n, bool)
        for i, _, f in parts:
            flag[i[f]] = True
        excluded[occ] = flag | hull[np.asarray(native, np.int64)]
    return ScanFusion(label, excluded, len(views))


class PredictionScore:
    """Confusion matrices ``[prediction, truth]`` per evaluation set and variant, over scans.

    Parameters
    ----------
    targets : dict of str -> (ClassSet, (n_pred,) int64)
        Evaluation sets and the table taking predicted ids into each.
    """

    def __init__(self, targets: dict):
        self.targets = targets
        self.conf = {(s, v): np.zeros((t.size, t.size), np.int64) for s, (t, _) in targets.items() for v in VARIANTS}
        self.points = 0
        self.labelled = {occ: 0 for occ in OCCLUSION}
        self.scans: list[int] = []

    def add(self, scan: int, native: np.ndarray, fused: ScanFusion) -> None:
        """Accumulate one scan (``native``: (n,) LiDAR truth)."""
        native = np.asarray(native, np.int64)
        self.points += len(native)
        self.scans.append(scan)
        for occ, exc in VARIANTS:
            lab = fused.label[occ]
            keep = lab >= 0
            if exc == "excluded":
                keep &= ~fused.excluded[occ]
            for s, (target, lut) in self.targets.items():
                n = target.size
                pred, gt = lut[lab[keep]], target.from_native[native[keep]]
                self.conf[s, (occ, exc)] += np.bincount(pred * n + gt, minlength=n * n).reshape(n, n)
        for occ in OCCLUSION:
            self.labelled[occ] += int((fused.label[occ] >= 0).sum())

    def result(self, name: str, variant: tuple[str, str]) -> dict:
        """Scores of evaluation set ``name`` in ``variant``."""
        target, _ = self.targets[name]
        return scores(self.conf[name, variant], target)

    def to_dict(self) -> dict:
        """Every set and variant."""
        return {s: {variant_key(v): self.result(s, v) for v in VARIANTS} for s in self.targets}


def scores(conf: np.ndarray, target: ClassSet) -> dict:
    """JSON-able IoU per class, mIoU (over all scored classes, and over those present), accuracy, points."""
    res = iou_from_confusion(conf, ignore=target.ignore, mean_over="all")
    present = iou_from_confusion(conf, ignore=target.ignore, mean_over="present")
    names = target.class_names()
    return {"points": int(conf.sum()),
            "points_scored": int(np.delete(conf, list(target.ignore), axis=1).sum()),
            "miou": _num(res.miou), "miou_present": _num(present.miou), "accuracy": _num(res.accuracy),
            "iou": {names[c]: _num(res.iou[c]) for c in range(len(names)) if res.present[c]},
            "truth": {names[c]: int(conf[:, c].sum()) for c in range(len(names)) if conf[:, c].sum()},
            "absent": [names[c] for c in range(len(names))
                       if names[c] and c not in target.ignore and not res.present[c]],
            "confusion_pred_truth": conf.tolist()}


def score_maps(pred_label: np.ndarray, truth_label: np.ndarray, target: ClassSet) -> dict:
    """Voxel-wise scores of two maps over the same voxels (labels in ``target`` ids)."""
    n = target.size
    conf = np.bincount(np.asarray(pred_label, np.int64) * n + np.asarray(truth_label, np.int64),
                       minlength=n * n).reshape(n, n)
    out = scores(conf, target)
    out["voxels"] = out.pop("points")
    out["voxels_scored"] = out.pop("points_scored")
    return out


def _num(x) -> float | None:
    return None if x is None or not np.isfinite(x) else float(x)
