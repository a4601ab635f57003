"""Projected image labels vs ray-cast LiDAR labels: confusion matrices and per-class IoU.

Per frame, :func:`fuse_frame` de-skews the scan, projects it into the camera (Eq. 1), runs
the occlusion test and reads the mask class and the 1-pixel-boundary flag of every point's
pixel. :class:`Agreement` accumulates one confusion matrix ``[LiDAR class, image class]``
per label set and variant:

* occlusion test ``off`` (seed 001: every point in the frustum takes its pixel's class) or ``on``;
* proxies ``included`` or ``excluded``: points whose LiDAR class or image class has a
  convex-hull label proxy (``class_table().hull_classes``: fence, vegetation, tree_crown)
  are left out. The hull fills the mask solid while LiDAR beams pass through the gaps, so a
  point on the wall behind a fence lies in a fence pixel: a disagreement by design;
* boundaries ``included`` or ``excluded``: points whose pixel has another class within one
  pixel are left out (the label pass samples one ray per pixel centre; the point lies
  anywhere in the pixel).

Label sets: ``native`` (the point's native class from ``native_labels/``) and ``unified11``.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from generator.fusion import projection as P
from generator.fusion.dataset import FusionFrame, deskewed
from generator.labels import class_table
from generator.labels.sets import label_sets as all_label_sets
from generator.stats.evaluate import iou_from_confusion

OCCLUSION = ("off", "on")
PROXIES = ("included", "excluded")
BOUNDARIES = ("included", "excluded")
VARIANTS = list(itertools.product(OCCLUSION, PROXIES, BOUNDARIES))
#: The variant the acceptance figure refers to.
HEADLINE = ("on", "excluded", "excluded")


def variant_key(v: tuple[str, str, str]) -> str:
    """``occlusion=on,proxies=excluded,boundaries=excluded``."""
    return f"occlusion={v[0]},proxies={v[1]},boundaries={v[2]}"


@dataclass
class FusedFrame:
    """Fusion result of one frame.

    Attributes
    ----------
    index : int
    xyz_start : (n, 3) float64
        All scan points de-skewed into the LiDAR frame at the sweep start, metres.
    proj : Projection
        The points in front of the camera and inside the image.
    visible : (m,) bool
        Occlusion test result per projected point.
    boundary : (m,) bool
        Pixel within 1 px of a mask boundary.
    image_class : (m,) uint8
        Mask class (native) at each projected point's pixel.
    lidar_class : (m,) uint8
        The point's own (ray-cast) native class.
    """

    index: int
    xyz_start: np.ndarray
    proj: P.Projection
    visible: np.ndarray
    boundary: np.ndarray
    image_class: np.ndarray
    lidar_class: np.ndarray


def fuse_frame(frame: FusionFrame, deskew: bool = True, abs_tol_m: float = P.ABS_TOL_M,
               rel_tol: float = P.REL_TOL, actors=None) -> FusedFrame:
    """De-skew, project, occlusion-test and label one frame (see the module docstring).

    ``actors``: instance id -> ``T_world_actor(t)`` (:func:`generator.fusion.movers.actor_poses`);
    with it (and ``deskew``) actor points are also de-skewed by their actor's motion to the
    image time (the sweep start); without it only the sensor's motion is undone.
    """
    xyz = deskewed(frame, deskew, actors)
    T = P.camera_from_lidar(frame.T_world_camera, frame.T_world_lidar_start)
    h, w = frame.class_id.shape
    proj = P.project(P.transform(T, xyz), frame.K, w, h)
    vis = P.visible(proj, frame.depth, frame.K, abs_tol_m, rel_tol)
    boundary = P.boundary_mask(frame.class_id)[proj.row, proj.col]
    return FusedFrame(frame.index, xyz, proj, vis, boundary, frame.class_id[proj.row, proj.col],
                      frame.native[proj.index])


def label_sets() -> dict[str, tuple[list[str], np.ndarray]]:
    """Agreement label sets: name -> (class names, lookup from native id); views of :mod:`generator.labels.sets`."""
    sets = all_label_sets()
    return {name: (list(sets[name].names), sets[name].from_native) for name in ("native", "unified11")}


class Agreement:
    """Confusion matrices ``[LiDAR class, image class]`` per label set and variant, over frames."""

    def __init__(self):
        self.sets = label_sets()
        self.conf = {(s, v): np.zeros((len(names),) * 2, np.int64)
                     for s, (names, _) in self.sets.items() for v in VARIANTS}
        self.points = 0
        self.in_view = 0
        self.visible = 0
        self.frames: list[int] = []

    def add(self, fused: FusedFrame) -> None:
        """Accumulate one frame."""
        hull = class_table().hull_classes
        self.points += len(fused.xyz_start)
        self.in_view += len(fused.proj.index)
        self.visible += int(fused.visible.sum())
        self.frames.append(fused.index)
        proxy = hull[fused.lidar_class] | hull[fused.image_class]
        for occ, prox, bnd in VARIANTS:
            keep = np.ones(len(fused.lidar_class), bool)
            if occ == "on":
                keep &= fused.visible
            if prox == "excluded":
                keep &= ~proxy
            if bnd == "excluded":
                keep &= ~fused.boundary
            for s, (names, lut) in self.sets.items():
                n = len(names)
                gt, pred = lut[fused.lidar_class[keep]], lut[fused.image_class[keep]]
                self.conf[s, (occ, prox, bnd)] += np.bincount(gt * n + pred, minlength=n * n).reshape(n, n)

    def agreement(self, label_set: str = "native", variant: tuple[str, str, str] = HEADLINE) -> float:
        """Fraction of counted points whose image class equals their LiDAR class (NaN if none)."""
        c = self.conf[label_set, variant]
        return float(np.trace(c) / c.sum()) if c.sum() else float("nan")

    def to_dict(self, settings: dict) -> dict:
        """JSON-able report: settings, counts, and per label set and variant the agreement,
        per-class IoU and confusion matrix."""
        out = {"settings": settings, "frames": self.frames, "points": self.points, "in_view": self.in_view,
               "visible": self.visible, "headline": {"variant": variant_key(HEADLINE),
                                                     "agreement_native": _num(self.agreement("native")),
                                                     "agreement_unified11": _num(self.agreement("unified11"))},
               "label_sets": {}}
        for s, (names, _) in self.sets.items():
            per = {}
            for v in VARIANTS:
                c = self.conf[s, v]
                res = iou_from_confusion(c, ignore=())
                per[variant_key(v)] = {
                    "points": int(c.sum()), "agreement": _num(self.agreement(s, v)), "miou": _num(res.miou),
                    "iou": {names[i]: _num(res.iou[i]) for i in range(len(names)) if res.evaluated[i]},
                    "lidar_points": {names[i]: int(c[i].sum()) for i in range(len(names)) if c[i].sum()},
                    "confusion_lidar_image": c.tolist()}
            out["label_sets"][s] = {"classes": names, "variants": per}
        return out


def _num(x: float) -> float | None:
    return None if x is None or not np.isfinite(x) else float(x)
