"""Synthetic KITTI ground truth and perturbed detections for the AP tests (deterministic from a seed).

``synthetic(seed)`` draws frames of Cars, Pedestrians, Cyclists (plus Vans, DontCare regions and a few
Trucks) with sizes, positions, occlusion and truncation across KITTI's difficulty limits, and
detections made from them: boxes shifted, scaled and turned by random amounts, some missed, some
false positives, scores that partly follow the overlap. The same seed gives the same files, so
numbers a reference evaluator printed for them once can be kept as a fixture.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from generator.formats.kitti_object import KittiObject, dont_care, write_labels

SIZES = {"Car": (1.55, 1.7, 4.2), "Van": (2.1, 1.9, 5.0), "Truck": (3.2, 2.5, 9.0),
         "Pedestrian": (1.75, 0.6, 0.8), "Cyclist": (1.75, 0.6, 1.8)}
F = 720.0
CX, CY = 620.0, 190.0


def _bbox(loc, dims):
    """The projected 2D box of a KITTI box (camera at the origin, focal F), as KITTI's labels give it."""
    h, w, length = dims
    x, y, z = loc
    xs = np.array([x - length / 2, x + length / 2])
    zs = np.array([z - w / 2, z + w / 2])
    u = F * xs[:, None] / zs[None] + CX
    v = F * np.array([y - h, y])[:, None] / zs[None] + CY
    return (float(max(u.min(), 0)), float(max(v.min(), 0)), float(min(u.max(), 1241)), float(min(v.max(), 374)))


def _object(g, cls):
    dims = tuple(float(s * g.uniform(0.9, 1.1)) for s in SIZES[cls])
    z = float(g.uniform(5, 55))
    loc = (float(g.uniform(-0.4, 0.4) * z), 1.65, z)
    ry = float(g.uniform(-np.pi, np.pi))
    bbox = _bbox(loc, dims)
    alpha = float((ry - np.arctan2(loc[0], loc[2]) + np.pi) % (2 * np.pi) - np.pi)
    occ = int(g.choice([0, 0, 0, 1, 1, 2, 3]))
    trunc = float(g.choice([0.0, 0.0, 0.0, g.uniform(0, 0.6)]))
    return KittiObject(cls, round(trunc, 2), occ, round(alpha, 4), tuple(round(v, 2) for v in bbox),
                       tuple(round(v, 2) for v in dims), tuple(round(v, 2) for v in loc), round(ry, 4))


def _detect(g, o: KittiObject, quality: float) -> KittiObject:
    """A detection of ``o``: moved up to ~0.6 m, resized up to ~15 %, turned up to ~0.4 rad; ``quality`` in (0, 1]."""
    shift = g.normal(0, 0.35 * (1.2 - quality), 3) * np.array([1, 0.3, 1])
    loc = tuple(round(float(v), 2) for v in np.asarray(o.location) + shift)
    dims = tuple(round(float(v * g.uniform(0.88, 1.12)), 2) for v in o.dimensions)
    ry = round(float(o.rotation_y + g.normal(0, 0.25)), 4)
    x1, y1, x2, y2 = o.bbox
    jitter = g.normal(0, 3.0 * (1.2 - quality), 4)
    bbox = (x1 + jitter[0], y1 + jitter[1], x2 + jitter[2], y2 + jitter[3])
    score = round(float(np.clip(quality * 0.8 + g.uniform(0, 0.2), 0.01, 0.999)), 4)
    return KittiObject(o.type, -1.0, -1, round(float(o.alpha + g.normal(0, 0.25)), 4), tuple(round(v, 2) for v in bbox),
                       dims, loc, ry, score)


def synthetic(seed: int = 26, frames: int = 24) -> tuple[list[list[KittiObject]], list[list[KittiObject]]]:
    """(ground truth, detections) per frame."""
    g = np.random.default_rng(seed)
    gts, dts = [], []
    for _ in range(frames):
        kinds = ["Car", "Car", "Car", "Pedestrian", "Pedestrian", "Cyclist", "Cyclist", "Van", "Truck"]
        gt = [_object(g, str(c)) for c in g.choice(kinds, size=int(g.integers(6, 12)))]
        if g.random() < 0.5:
            gt.append(dont_care((float(g.uniform(0, 1000)), 170.0, float(g.uniform(1000, 1240)), 200.0)))
        dt = [_detect(g, o, float(g.uniform(0.2, 1.0))) for o in gt if o.type != "DontCare" and g.random() < 0.85]
        for _ in range(int(g.integers(0, 3))):   # false positives
            fake = _object(g, str(g.choice(["Car", "Pedestrian", "Cyclist"])))
            dt.append(_detect(g, fake, float(g.uniform(0.1, 0.6))))
        gts.append(gt)
        dts.append(dt)
    return gts, dts


def as_predictions(gt: list[KittiObject]) -> list[KittiObject]:
    """Ground truth submitted as detections (score 1, DontCare regions left out)."""
    return [KittiObject(o.type, o.truncated, o.occluded, o.alpha, o.bbox, o.dimensions, o.location, o.rotation_y, 1.0)
            for o in gt if o.type != "DontCare"]


def write_dir(folder: Path, frames: list[list[KittiObject]]) -> list[str]:
    """Write ``folder/NNNNNN.txt`` per frame; return the ids."""
    folder.mkdir(parents=True, exist_ok=True)
    ids = []
    for k, objs in enumerate(frames):
        (folder / f"{k:06d}.txt").write_text(write_labels(objs))
        ids.append(f"{k:06d}")
    return ids
