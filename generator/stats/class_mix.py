"""How far the data's class mix is from real driving data, and which benchmark classes it has.

* LiDAR: points per SemanticKITTI learning class (the 19 of the benchmark, via the label
  config's ``learning_map``) over every scan of ``lidar/sequences/*/labels``, beside
  SemanticKITTI's own distribution (the reference config's ``content``, mapped the same way,
  class 0 left out and renormalised), with the total-variation distance
  ``TV = 1/2 sum_c |p_c - q_c|`` (0 = the same mix, 1 = disjoint).
* Images: which of Cityscapes' 19 train classes appear (pixel counts from the image
  metadata) and which of SemanticKITTI's 19 appear in the scans.

A statistics module (``load`` / ``section``, see :mod:`generator.stats`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generator.formats import semantickitti as sk
from generator.labels import class_table
from generator.labels.cityscapes import cityscapes_labels
from generator.labels.sets import label_sets
from generator.stats import images as image_stats
from generator.stats.report import Section, Table

#: Cityscapes' 19 train classes: (label id, name), in train-id order (``generator/labels/cityscapes.yaml``).
CITYSCAPES_TRAIN = cityscapes_labels().train_classes


@dataclass
class MixData:
    """Point counts per learning class (20,) int64 and Cityscapes label-id pixel counts (256,) int64."""

    root: Path
    points: np.ndarray
    scans: int
    pixels: np.ndarray
    images: int


def reference_distribution() -> np.ndarray:
    """(20,) float64 SemanticKITTI's share of points per learning class (index 0 = 0; 1..19 sum to 1)."""
    t = class_table()
    lut = label_sets()["semantickitti"].from_raw
    p = np.zeros(20)
    for raw, share in t.sk_config["content"].items():
        p[lut[int(raw)]] += float(share)
    p[0] = 0.0
    return p / p.sum()


def distribution(points: np.ndarray) -> np.ndarray:
    """(20,) float64 share of points per learning class, class 0 left out (zeros if no points)."""
    p = np.asarray(points, np.float64).copy()
    p[0] = 0.0
    return p / p.sum() if p.sum() else p


def tv_distance(p: np.ndarray, q: np.ndarray) -> float:
    """Total-variation distance ``1/2 sum |p - q|`` of two distributions."""
    return 0.5 * float(np.abs(np.asarray(p) - np.asarray(q)).sum())


def count_points(lidar_root: Path) -> tuple[np.ndarray, int]:
    """(20,) int64 points per learning class over every labelled scan under ``lidar_root``, and the scan count."""
    lut = label_sets()["semantickitti"].from_raw
    counts, scans = np.zeros(20, np.int64), 0
    for name in sk.list_sequences(lidar_root):
        seq = sk.Sequence(lidar_root, name)
        if not seq.has_labels:
            continue
        for k in seq.frames:
            sem, _ = sk.read_labels(seq.label_path(k))
            sk.check_raw_ids(sem, seq.label_path(k))
            counts += np.bincount(lut[sem], minlength=20)[:20]
            scans += 1
    return counts, scans


def load(root: Path) -> MixData | None:
    """Point and pixel counts of the dataset at ``root`` (None when it has neither scans nor images)."""
    root = Path(root)
    points, scans = np.zeros(20, np.int64), 0
    lidar = root / "lidar" if (root / "lidar" / "sequences").is_dir() else root  # a dataset, or a lidar-only output
    if (lidar / "sequences").is_dir():
        points, scans = count_points(lidar)
    pixels, images = np.zeros(256, np.int64), 0
    data = image_stats.load(root)  # the images section's parse of the metadata (classes_present)
    if data is not None:
        np.add.at(pixels, class_table().to_cityscapes, data.totals())
        images = len(data.records)
    if not scans and not images:
        return None
    return MixData(root, points, scans, pixels, images)


def section(data: MixData) -> Section:
    """The class-mix section: LiDAR distribution vs SemanticKITTI with the TV distance, class coverage."""
    names = label_sets()["semantickitti"].names
    summary, tables = [], []
    if data.scans:
        p, q = distribution(data.points), reference_distribution()
        tv = tv_distance(p, q)
        summary.append(f"LiDAR class mix over {data.scans:,} scans: total-variation distance {tv:.3f} from "
                       "SemanticKITTI's (0 = the same mix)")
        rows = [[names[c], int(data.points[c]), f"{100 * p[c]:.2f}", f"{100 * q[c]:.2f}"] for c in range(1, 20)]
        tables.append(Table("lidar_class_mix", "LiDAR points per SemanticKITTI learning class",
                            ["Class", "Points", "Share %", "SemanticKITTI %"],
                            ["class", "points", "share_pct", "semantickitti_pct"], rows,
                            [f"TV distance = {tv:.4f}; unlabeled points left out; SemanticKITTI % from the "
                             "reference label config's content, mapped through learning_map."]))
    have_sk = [names[c] for c in range(1, 20) if data.points[c] > 0]
    have_cs = [n for i, n in CITYSCAPES_TRAIN if data.pixels[i] > 0]
    summary.append(
        f"SemanticKITTI learning classes in the scans: {len(have_sk)} of 19"
        + (f" (missing: {', '.join(n for n in names[1:20] if n not in have_sk)})" if len(have_sk) < 19 else "")
    )
    summary.append(f"Cityscapes train classes in the images: {len(have_cs)} of 19"
                   + (f" (missing: {', '.join(n for _, n in CITYSCAPES_TRAIN if n not in have_cs)})"
                      if len(have_cs) < 19 else ""))
    rows = [[n, int(data.pixels[i])] for i, n in CITYSCAPES_TRAIN]
    tables.append(Table("cityscapes_classes", "Pixels per Cityscapes train class", ["Class", "Pixels"],
                        ["class", "pixels"], rows))
    return Section("Class mix", summary, tables)
