"""The detection view of the class table (``detection.yaml``): which things get boxes and their names.

A box class is a native *thing* class; a ridden two-wheeler's box is named by its rider's class and
merges the vehicle classes listed in ``parts``. Checked on load: every class and part is a native thing
class, every part belongs to one box class, every group and KITTI type is a known one.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

from generator.labels.registry import _load_yaml, class_table

GROUPS = ("vehicle", "cycle", "pedestrian")
KITTI_TYPES = ("Car", "Van", "Truck", "Pedestrian", "Person_sitting", "Cyclist", "Tram", "Misc", "DontCare")


@dataclass(frozen=True)
class BoxClass:
    """One row of ``detection.yaml`` ``boxes``.

    Attributes
    ----------
    name : str
        Native class naming the box (``"car"``, ``"bicyclist"`` ...).
    group : str
        nuScenes attribute family: ``"vehicle"``, ``"cycle"`` or ``"pedestrian"``.
    kitti : str
        KITTI object type.
    parts : tuple of str
        Native vehicle classes merged into this box (a ridden two-wheeler's vehicle).
    """

    name: str
    group: str
    kitti: str
    parts: tuple[str, ...] = ()


@dataclass(frozen=True)
class DetectionClasses:
    """The box classes, the merged parts and the KITTI names by asset kind."""

    boxes: dict[str, BoxClass]
    kind_kitti: dict[str, str]

    @property
    def part_of(self) -> dict[str, str]:
        """Native class of a merged part -> the box class it belongs to."""
        return {p: b.name for b in self.boxes.values() for p in b.parts}

    def kitti_type(self, cls: str, kind: str = "") -> str:
        """KITTI type of a box of class ``cls`` built from asset ``kind``."""
        return self.kind_kitti.get(kind) or self.boxes[cls].kitti


@functools.cache
def detection_classes() -> DetectionClasses:
    """The parsed and checked ``detection.yaml``."""
    doc = _load_yaml("detection.yaml")
    table = class_table()
    things = {r.name for r in table.rows if r.thing}
    boxes = {}
    for name, row in doc["boxes"].items():
        b = BoxClass(name, row["group"], row["kitti"], tuple(row.get("parts", ())))
        bad = [c for c in (name, *b.parts) if c not in things]
        if bad or b.group not in GROUPS or b.kitti not in KITTI_TYPES:
            raise ValueError(f"detection.yaml: box class {name}: not a thing class, or unknown group/KITTI type")
        boxes[name] = b
    parts = [p for b in boxes.values() for p in b.parts]
    if len(set(parts)) != len(parts) or set(parts) & set(boxes):
        raise ValueError("detection.yaml: a part belongs to one box class and is no box class itself")
    kinds = {k: v["kitti"] for k, v in (doc.get("kinds") or {}).items()}
    if not set(kinds.values()) <= set(KITTI_TYPES):
        raise ValueError("detection.yaml: kinds: unknown KITTI type")
    return DetectionClasses(boxes, kinds)
