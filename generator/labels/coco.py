"""The COCO view of the class table (``coco.yaml``): categories of the instance and panoptic exports."""

from __future__ import annotations

import functools

from generator.labels.registry import _load_yaml, class_table


@functools.cache
def coco_categories() -> list[dict]:
    """COCO ``categories`` records (``id``, ``name``, ``supercategory``, ``isthing``, ``color``, ``coco``),
    one per native class but unlabeled (COCO panoptic's void), in native id order.

    Raises
    ------
    ValueError
        ``coco.yaml`` does not list every such class exactly once.
    """
    doc = _load_yaml("coco.yaml")["categories"]
    rows = [r for r in class_table().rows if r.id != 0]
    if set(doc) != {r.name for r in rows}:
        raise ValueError("coco.yaml: must list every native class but unlabeled, and nothing else")
    return [{"id": r.id, "name": r.name, "supercategory": str(doc[r.name]["supercategory"]), "isthing": int(r.thing),
             "color": [int(c) for c in r.color], "coco": doc[r.name].get("coco")} for r in rows]
