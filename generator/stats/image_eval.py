"""Pixel-level semantic labelling scores of image predictions, exactly as cityscapesScripts computes them.

The conventions of ``cityscapesscripts.evaluation.evalPixelLevelSemanticLabeling`` (v2.3.0), on Cityscapes
label ids 0..33 (ground truth and prediction):

* one confusion matrix ``[ground truth, prediction]`` pooled over every pixel of every image;
* class IoU ``TP / (TP + FP + FN)`` for the 19 classes with a train id (the others are
  ``ignoreInEval``: NaN): FN is the rest of the class's row (predictions of ignored ids included), FP
  counts only pixels whose ground truth is a *non-ignored* other class -- a prediction over void
  ground truth costs nothing;
* iIoU: TP and FN of each ground-truth instance (``instanceIds > 1000``, of a non-ignored class) weighted
  by ``avgClassSize[class] / instance size`` (:data:`AVG_CLASS_SIZE`, the script's constants); FP as for IoU;
* categories: the same over Cityscapes' categories (flat, construction, object, nature, sky, human,
  vehicle; void has no evaluated class: NaN), using only the evaluated ids of each category, and
  category iIoU for the categories whose classes all have instances (human, vehicle);
* averages: the mean of the scores that are not NaN (a class absent from ground truth and never
  predicted over non-void ground truth is NaN and left out).

IoU and its averages come out bit-identical to the script's; iIoU sums floats in image order, so
another image order changes it in the last bits only. Beyond the script: the same scores per image
(``per_image``), and seed 001's per-image table (:func:`seed001_table`): per image the plain IoU of
every label id present in ground truth or prediction (nothing ignored, as the paper scored its 34
classes), averaged per class over the images, best first; and the same on seed 001's 8 merged classes.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from generator.errors import SpecError
from generator.labels.class_sets import builtin_sets, cityscapes_table

N_IDS = 34
#: cityscapesScripts ``args.avgClassSize``: mean instance size (pixels) per class, the iIoU weights.
AVG_CLASS_SIZE = {
    "bicycle": 4672.3249222261, "caravan": 36771.8241758242, "motorcycle": 6298.7200839748,
    "rider": 3930.4788056518, "bus": 35732.1511111111, "train": 67583.7075812274, "car": 12794.0202738185,
    "person": 3462.4756337644, "truck": 27855.1264367816, "trailer": 16926.9763313609,
}
#: Label ids with instances (cityscapesScripts ``hasInstances``): person .. bicycle.
INSTANCE_IDS = (24, 25, 26, 27, 28, 29, 30, 31, 32, 33)


@functools.cache
def _labels() -> dict:
    cs = cityscapes_table()
    seed = builtin_sets()["seed001"]  # Cityscapes' categories over the 34 ids (seed001.yaml)
    names = cs["names"]
    ignored = np.array([t == 255 for t in cs["train"]])
    category = [seed.names[int(seed.from_base[i])] for i in range(N_IDS)]
    cats = list(dict.fromkeys(category))
    inst_cats = [c for c in cats if all(i in INSTANCE_IDS for i in range(N_IDS) if category[i] == c)]
    return {"names": names, "ignored": ignored, "category": category, "categories": cats,
            "instance_categories": inst_cats, "seed": seed}


def _iou(conf: np.ndarray, ids: list[int], ignored: np.ndarray, other: np.ndarray,
         tp_fn: tuple[float, float] | None = None) -> float:
    """IoU of the id group ``ids`` from a ``[gt, pred]`` matrix; ``other``: rows counted as FP."""
    tp = int(conf[np.ix_(ids, ids)].sum())
    fn = int(conf[ids, :].sum()) - tp
    fp = int(conf[np.ix_(np.flatnonzero(other), ids)].sum())
    if tp_fn is not None:
        tp, fn = tp_fn
    denom = tp + fp + fn
    return float("nan") if denom == 0 else tp / denom


class PixelEvaluator:
    """Accumulates image pairs and scores them as cityscapesScripts does (see the module docstring)."""

    def __init__(self):
        lab = _labels()
        self.conf = np.zeros((N_IDS, N_IDS), np.int64)  # [ground truth, prediction]
        self.inst = {n: [0.0, 0.0] for i, n in enumerate(lab["names"]) if i in INSTANCE_IDS and not lab["ignored"][i]}
        self.inst_cat = {c: [0.0, 0.0] for c in lab["instance_categories"]}
        self.images: list[dict] = []
        self._seed_conf: list[np.ndarray] = []

    def add(self, name: str, gt: np.ndarray, pred: np.ndarray, instances: np.ndarray | None, source: str) -> None:
        """Add one image.

        Parameters
        ----------
        name : str
            The image's name in the per-image table (its Cityscapes stem or ``image_2`` file name).
        gt, pred : (H, W) integer
            Cityscapes label ids (``pred`` already checked to hold ids 0..33).
        instances : (H, W) integer or None
            Ground-truth ``instanceIds`` (label id x 1000 + k); None skips iIoU for this image.
        source : str
            The prediction file (named in errors).
        """
        self._lab = _labels()
        gt = np.asarray(gt, np.int64)
        pred = np.asarray(pred, np.int64)
        if gt.shape != pred.shape:
            raise SpecError(source, "size", f"{pred.shape[1]} x {pred.shape[0]} pixels, ground truth is "
                                            f"{gt.shape[1]} x {gt.shape[0]}")
        bad = np.setdiff1d(np.unique(gt), np.arange(N_IDS))
        if bad.size:
            raise SpecError(f"ground truth of {name}", "ids", f"unknown Cityscapes label ids {bad[:8].tolist()}")
        conf = np.bincount(gt.ravel() * N_IDS + pred.ravel(), minlength=N_IDS * N_IDS).reshape(N_IDS, N_IDS)
        self.conf += conf
        if instances is not None:
            self._add_instances(np.asarray(instances, np.int64), pred)
        scores = self.class_scores(conf)
        self.images.append({"image": name, "prediction": source, "pixels": int(gt.size),
                            "iou": {k: _num(v) for k, v in scores.items() if not math.isnan(v)},
                            "miou": _num(_mean(scores))})
        self._seed_conf.append(conf)

    def _add_instances(self, instances: np.ndarray, pred: np.ndarray) -> None:
        lab = self._lab
        cat_masks = {c: np.isin(pred, [i for i in INSTANCE_IDS if lab["category"][i] == c]) for c in self.inst_cat}
        for inst_id in np.unique(instances[instances > 1000]):
            label = int(inst_id // 1000)
            if label >= N_IDS or lab["ignored"][label]:
                continue
            name = lab["names"][label]
            mask = instances == inst_id
            size = int(np.count_nonzero(mask))
            tp = int(np.count_nonzero(pred[mask] == label))
            weight = AVG_CLASS_SIZE[name] / float(size)
            self.inst[name][0] += float(tp) * weight
            self.inst[name][1] += float(size - tp) * weight
            cat = lab["category"][label]
            if cat in self.inst_cat:
                cat_tp = int(np.count_nonzero(mask & cat_masks[cat]))
                self.inst_cat[cat][0] += float(cat_tp) * weight
                self.inst_cat[cat][1] += float(size - cat_tp) * weight

    # -- scores ---------------------------------------------------------------------------------------------
    def class_scores(self, conf: np.ndarray | None = None, instances: bool = False) -> dict[str, float]:
        """Label name -> IoU (or iIoU) for every id 0..33 (NaN: ignored or nowhere)."""
        lab = _labels()
        conf = self.conf if conf is None else conf
        out = {}
        for i, name in enumerate(lab["names"]):
            if lab["ignored"][i] or (instances and name not in self.inst):
                out[name] = float("nan")
                continue
            other = ~lab["ignored"].copy()
            other[i] = False
            out[name] = _iou(conf, [i], lab["ignored"], other, tuple(self.inst[name]) if instances else None)
        return out

    def category_scores(self, instances: bool = False) -> dict[str, float]:
        """Category -> IoU (or iIoU) as the script computes it."""
        lab = _labels()
        out = {}
        for cat in lab["categories"]:
            in_cat = np.array([c == cat for c in lab["category"]])
            other = ~lab["ignored"] & ~in_cat
            if instances:
                if cat not in self.inst_cat:
                    out[cat] = float("nan")
                    continue
                ids = [i for i in INSTANCE_IDS if lab["category"][i] == cat]
                out[cat] = _iou(self.conf, ids, lab["ignored"], other, tuple(self.inst_cat[cat]))
                continue
            ids = [i for i in range(N_IDS) if in_cat[i] and not lab["ignored"][i]]
            out[cat] = _iou(self.conf, ids, lab["ignored"], other) if ids else float("nan")
        return out

    def result(self) -> dict:
        """JSON-able scores (``None`` for NaN); key names follow the script's result JSON."""
        classes, inst = self.class_scores(), self.class_scores(instances=True)
        cats, cat_inst = self.category_scores(), self.category_scores(instances=True)
        return {
            "conventions": "cityscapesScripts evalPixelLevelSemanticLabeling (v2.3.0): confusion [gt, pred] pooled "
                           "over all pixels; FP only over non-ignored ground truth; averages over non-NaN scores",
            "images": len(self.images), "pixels": int(self.conf.sum()),
            "classScores": _nums(classes), "classInstScores": _nums(inst),
            "categoryScores": _nums(cats), "categoryInstScores": _nums(cat_inst),
            "averageScoreClasses": _num(_mean(classes)), "averageScoreInstClasses": _num(_mean(inst)),
            "averageScoreCategories": _num(_mean(cats)), "averageScoreInstCategories": _num(_mean(cat_inst)),
            "confMatrix_gt_pred": self.conf.tolist(),
            "per_image": self.images,
            "seed001": seed001_table(self._seed_conf),
        }


def seed001_table(confs: list[np.ndarray]) -> dict:
    """Seed 001's per-image table: per-class IoU averaged over images, best first, 34 ids and 8 merged.

    Per image, a class counts when it is in the image's ground truth or prediction (union > 0);
    its plain IoU there (nothing ignored) is averaged over those images.
    """
    lab = _labels()
    seed = lab["seed"]
    merge = seed.from_base  # (34,) -> 0..7
    out = {}
    for key, names, project in (("classes", lab["names"], lambda c: c),
                                ("merged_8", seed.class_names(), lambda c: _merge(c, merge, seed.size))):
        sums, counts = np.zeros(len(names)), np.zeros(len(names), np.int64)
        for conf in confs:
            c = project(conf)
            tp = np.diag(c).astype(np.float64)
            union = c.sum(0) + c.sum(1) - tp
            present = union > 0
            sums[present] += tp[present] / union[present]
            counts[present] += 1
        rows = [{"class": names[i], "iou": float(sums[i] / counts[i]), "images": int(counts[i])}
                for i in range(len(names)) if counts[i]]
        out[key] = sorted(rows, key=lambda r: (-r["iou"], r["class"]))
    return out


def _merge(conf: np.ndarray, lut: np.ndarray, n: int) -> np.ndarray:
    out = np.zeros((n, n), np.int64)
    np.add.at(out, (lut[:, None], lut[None, :]), conf)
    return out


def _mean(scores: dict[str, float]) -> float:
    valid = [v for v in scores.values() if not math.isnan(v)]
    return sum(valid) / len(valid) if valid else float("nan")


def _num(x: float) -> float | None:
    return None if x is None or math.isnan(x) else float(x)


def _nums(d: dict[str, float]) -> dict[str, float | None]:
    return {k: _num(v) for k, v in d.items()}


def format_table(result: dict) -> str:
    """Plain-text summary: class IoU / iIoU, the averages, categories, seed 001's top-10."""
    lines = [f"{'class':<16} {'IoU %':>7} {'iIoU %':>7}"]
    for name, v in result["classScores"].items():
        if v is None and result["classInstScores"].get(name) is None:
            continue
        iv = result["classInstScores"].get(name)
        lines.append(f"{name:<16} {_pct(v):>7} {_pct(iv):>7}")
    lines.append(f"{'Score Average':<16} {_pct(result['averageScoreClasses']):>7} "
                 f"{_pct(result['averageScoreInstClasses']):>7}")
    lines.append("")
    lines.append(f"{'category':<16} {'IoU %':>7} {'iIoU %':>7}")
    for name, v in result["categoryScores"].items():
        if v is None:
            continue
        lines.append(f"{name:<16} {_pct(v):>7} {_pct(result['categoryInstScores'].get(name)):>7}")
    lines.append(f"{'Score Average':<16} {_pct(result['averageScoreCategories']):>7} "
                 f"{_pct(result['averageScoreInstCategories']):>7}")
    lines.append("")
    lines.append(f"seed 001 table (IoU per image, averaged over {result['images']} images; top 10 of 34 ids):")
    for r in result["seed001"]["classes"][:10]:
        lines.append(f"  {r['class']:<16} {r['iou']:.4f}  ({r['images']} images)")
    return "\n".join(lines)


def _pct(x) -> str:
    return "nan" if x is None else f"{100 * x:.2f}"
