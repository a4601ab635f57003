"""3D box annotations per class: seed 002's Table 1 ("number of annotations of the synthetic dataset").

An annotation is one box in one LiDAR sweep: every thing that appears in that point cloud (as seed
002 counts them: every object the semantic LiDAR sees, in every one of its 100-sweep scenes). Read
from each sequence's box file (``boxes/NN.npz``, the records that ``generate`` keeps: at least
``min_points`` LiDAR points, 1 by default), else from its OpenLABEL file (cuboids per frame).

Classes are seed 002's six, the nuScenes detection classes of its study: a box class maps to its
nuScenes category and that to its detection class (``generator/labels/nuscenes.yaml``); boxes of
other detection classes (construction vehicles, trailers) and of none are counted as ``other``. The
paper's own counts stand beside ours, with each class's share of the total.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path

from generator.formats.box_file import read_box_file
from generator.imaging import meta_fields as md
from generator.labels.nuscenes import SEED002_CLASSES, nuscenes_labels
from generator.stats.report import Section, Table

log = logging.getLogger(__name__)

#: Seed 002 Table 1 (9,600 point clouds: 96 scenes x 100).
SEED002_TABLE1 = {"car": 48_878, "truck": 26_273, "bus": 13_097, "pedestrian": 29_373, "motorcycle": 20_526,
                  "bicycle": 18_177}
SEED002_SWEEPS = 9_600


@dataclass
class AnnotationData:
    """Box counts of a dataset: per seed-002 class (and ``other``), sweeps counted, where they came from."""

    counts: dict[str, int]
    sweeps: int
    sources: list[str]


def _sequences(root: Path) -> list[str]:
    base = Path(root) / "lidar" / "sequences"
    return sorted(p.name for p in base.glob("[0-9][0-9]")) if base.is_dir() else []


def load(root: Path) -> AnnotationData | None:
    """Counts from the box files (or OpenLABEL files) of ``root``'s sequences; None when it has neither."""
    labels = nuscenes_labels()
    counts = {c: 0 for c in (*SEED002_CLASSES, "other")}
    sweeps, sources = 0, []

    def add(cls: str, kind: str = "") -> None:
        name = labels.detection_class(cls, kind) if cls in labels.boxes else None
        counts[name if name in SEED002_CLASSES else "other"] += 1

    for name in _sequences(root):
        box_path, ol_path = Path(root) / "boxes" / f"{name}.npz", Path(root) / "openlabel" / f"{name}.json"
        if box_path.is_file():
            bf = read_box_file(box_path)
            for j in sorted(bf.sweeps):
                for r in bf.records(j):
                    add(r.cls, r.kind)
            sweeps += len(bf.sweeps)
            sources.append(f"boxes/{name}.npz")
        elif ol_path.is_file():
            doc = md.load_metadata(ol_path)
            ol = doc.get("openlabel", {}) if isinstance(doc, dict) else {}
            objects, frames = ol.get("objects") or {}, ol.get("frames") or {}
            for f in frames.values():
                for uid in (f.get("objects") or {}) if isinstance(f, dict) else {}:
                    add(str((objects.get(uid) or {}).get("type", "")))
            sweeps += len(frames)
            sources.append(f"openlabel/{name}.json")
    if not sources:
        return None
    return AnnotationData(counts, sweeps, sources)


def section(data: AnnotationData) -> Section:
    """Seed 002's Table 1 beside the paper's numbers."""
    total = sum(data.counts.values())
    ref_total = sum(SEED002_TABLE1.values())
    share = lambda n, t: f"{100 * n / t:.1f}" if t else "-"   # noqa: E731
    rows = [[c, data.counts[c], share(data.counts[c], total), SEED002_TABLE1[c], share(SEED002_TABLE1[c], ref_total)]
            for c in SEED002_CLASSES]
    rows.append(["other", data.counts["other"], share(data.counts["other"], total), 0, share(0, ref_total)])
    rows.append(["total", total, "100.0" if total else "-", ref_total, "100.0"])
    per = total / data.sweeps if data.sweeps else 0.0
    table = Table("table1_annotations", "Seed 002 Table 1: 3D box annotations per class",
                  ["Object class", "Annotations", "Share %", "Seed 002", "Seed 002 share %"],
                  ["class", "annotations", "share_pct", "seed002", "seed002_share_pct"], rows,
                  [f"One annotation = one box in one LiDAR sweep (every thing with points in it); {data.sweeps:,} "
                   f"sweeps here ({per:.1f} boxes per sweep), {SEED002_SWEEPS:,} in seed 002 "
                   f"({ref_total / SEED002_SWEEPS:.1f} per sweep). Classes: nuScenes detection classes through "
                   "generator/labels/nuscenes.yaml; 'other' = construction vehicles, trailers. From "
                   + ", ".join(data.sources[:4]) + (" ..." if len(data.sources) > 4 else "") + "."])
    return Section("3D box annotations", [f"{total:,} box annotations in {data.sweeps:,} LiDAR sweeps "
                                          f"({per:.1f} per sweep; seed 002: {ref_total / SEED002_SWEEPS:.1f})"],
                   [table])
