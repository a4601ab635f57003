"""The nuScenes view of the box classes (``nuscenes.yaml``): categories, attributes, visibility bins.

Checked on load: every box class of ``detection.yaml`` maps to one of the listed categories (and every
kind override too), the attribute list is nuScenes' eight, the visibility bins are its four.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

from generator.labels.detection import detection_classes
from generator.labels.registry import _load_yaml

#: The attributes nuScenes v1.0 defines (attribute.json), in its order.
ATTRIBUTES = ("vehicle.moving", "vehicle.stopped", "vehicle.parked", "cycle.with_rider", "cycle.without_rider",
              "pedestrian.sitting_lying_down", "pedestrian.standing", "pedestrian.moving")
#: The six classes seed 002 scores (its Tables 1-3), in its order.
SEED002_CLASSES = ("car", "truck", "bus", "pedestrian", "motorcycle", "bicycle")
#: Visibility bin edges (fraction visible): bin token ``str(i + 1)`` holds [edge i, edge i + 1).
VISIBILITY_EDGES = (0.0, 0.4, 0.6, 0.8, 1.0)


@dataclass(frozen=True)
class NuScenesLabels:
    """Parsed ``nuscenes.yaml``.

    Attributes
    ----------
    categories : dict of str to str
        nuScenes category name -> description, in nuScenes' order.
    boxes : dict of str to str
        Box class (``detection.yaml``) -> category name.
    kinds : dict of str to str
        Asset kind -> category name where it differs from its class's.
    attributes : dict of str to str
        Attribute name -> description.
    visibility : list of dict
        ``{"token", "level", "description"}`` per bin.
    detection : dict of str to str
        Category -> the detection benchmark class it folds into (categories it scores only).
    """

    categories: dict[str, str]
    boxes: dict[str, str]
    kinds: dict[str, str]
    attributes: dict[str, str]
    visibility: list[dict]
    detection: dict[str, str]

    def category(self, cls: str, kind: str = "") -> str:
        """The nuScenes category of a box of class ``cls`` built from asset ``kind``."""
        return self.kinds.get(kind) or self.boxes[cls]

    def detection_class(self, cls: str, kind: str = "") -> str | None:
        """The detection benchmark class of a box (``car``, ``pedestrian``...), None when it scores none."""
        return self.detection.get(self.category(cls, kind))


def visibility_token(fraction: float) -> str:
    """nuScenes visibility token (``"1"``..``"4"``) of a visible ``fraction`` in [0, 1]."""
    for i, hi in enumerate(VISIBILITY_EDGES[1:-1]):
        if fraction < hi:
            return str(i + 1)
    return str(len(VISIBILITY_EDGES) - 1)


@functools.cache
def nuscenes_labels() -> NuScenesLabels:
    """The parsed and checked ``nuscenes.yaml``."""
    doc = _load_yaml("nuscenes.yaml")
    cats = {str(k): str(v) for k, v in doc["categories"].items()}
    boxes = {str(k): str(v) for k, v in doc["boxes"].items()}
    kinds = {str(k): str(v) for k, v in (doc.get("kinds") or {}).items()}
    attrs = {str(k): str(v) for k, v in doc["attributes"].items()}
    missing = set(detection_classes().boxes) - set(boxes)
    unknown = {c for c in [*boxes.values(), *kinds.values()] if c not in cats}
    if missing or unknown or set(boxes) - set(detection_classes().boxes):
        raise ValueError(f"nuscenes.yaml: box classes without a category {sorted(missing)}, unknown categories "
                         f"{sorted(unknown)}, or classes that are no box class")
    if tuple(attrs) != ATTRIBUTES:
        raise ValueError("nuscenes.yaml: attributes must be nuScenes' eight, in its order")
    vis = [dict(v) for v in doc["visibility"]]
    if [v["token"] for v in vis] != [str(i) for i in range(1, len(VISIBILITY_EDGES))]:
        raise ValueError("nuscenes.yaml: visibility tokens must be 1..4")
    det = {str(c): str(d) for d, cs in doc["detection"].items() for c in cs}
    if set(det) - set(cats) or len(doc["detection"]) != 10:
        raise ValueError("nuscenes.yaml: detection: ten classes, each of listed categories")
    return NuScenesLabels(cats, boxes, kinds, attrs, vis, det)
