"""COCO instance and panoptic records of labelled images (class and instance maps in, JSON-able records out).

Categories are the native classes (:func:`generator.labels.coco.coco_categories`: id = native id).

* **Instances** (``instances_<split>.json``): one annotation per *thing segment* -- the pixels of one
  instance id and one thing class (a moving cyclist is one actor whose rider and bicycle pixels carry
  two classes: two annotations, rider and bicycle, as COCO and Cityscapes draw them). ``segmentation``
  is COCO's compressed RLE (``{"size": [h, w], "counts": str}``, made by ``pycocotools.mask.encode``),
  ``bbox`` ``[x, y, w, h]`` in pixels (top-left origin), ``area`` in pixels, ``iscrowd`` 0.
* **Panoptic** (``panoptic_<split>.json`` + one PNG per image): every pixel in one segment, id encoded
  as ``R + 256 G + 256^2 B``; each thing segment as above, each stuff class one segment; unlabeled
  pixels are void (id 0, listed nowhere), as COCO panoptic defines them.
"""

from __future__ import annotations

import numpy as np

from generator.errors import UserError
from generator.labels import class_table

INSTALL_HINT = 'the COCO export needs pycocotools: pip install -e ".[detection]"'


def mask_api():
    """``pycocotools.mask``, or one line saying how to install it."""
    try:
        from pycocotools import mask
    except ImportError:
        raise UserError(INSTALL_HINT) from None
    return mask


def thing_segments(class_id: np.ndarray, instance: np.ndarray) -> list[tuple[int, int, np.ndarray]]:
    """``(class id, instance id, (H, W) bool mask)`` of every thing segment, sorted by (instance, class).

    Parameters
    ----------
    class_id : (H, W) integer
        Native class per pixel.
    instance : (H, W) integer
        Instance id per pixel (0 for stuff).
    """
    thing = np.array([r.thing for r in class_table().rows], bool)
    cls = np.asarray(class_id, np.int64)
    inst = np.asarray(instance, np.int64)
    sel = thing[cls] & (inst > 0)
    if not sel.any():
        return []
    keys = np.unique(inst[sel] * 256 + cls[sel])
    key_map = np.where(sel, inst * 256 + cls, -1)
    return [(int(k % 256), int(k // 256), key_map == k) for k in keys]


def rle(mask: np.ndarray) -> dict:
    """COCO compressed RLE of a (H, W) bool mask, JSON-ready (``counts`` a str)."""
    m = mask_api().encode(np.asfortranarray(mask.astype(np.uint8)))
    return {"size": [int(v) for v in m["size"]], "counts": m["counts"].decode("ascii")}


def _box(mask: np.ndarray) -> list[float]:
    rows, cols = np.flatnonzero(mask.any(1)), np.flatnonzero(mask.any(0))
    return [float(cols[0]), float(rows[0]), float(cols[-1] - cols[0] + 1), float(rows[-1] - rows[0] + 1)]


def instance_annotations(image_id: int, class_id: np.ndarray, instance: np.ndarray, next_id: int) -> list[dict]:
    """COCO ``annotations`` of one image's thing segments (ids from ``next_id`` on)."""
    out = []
    for k, (cls, inst, mask) in enumerate(thing_segments(class_id, instance)):
        out.append({"id": next_id + k, "image_id": int(image_id), "category_id": cls, "segmentation": rle(mask),
                    "area": int(mask.sum()), "bbox": _box(mask), "iscrowd": 0, "instance_id": inst})
    return out


def panoptic(class_id: np.ndarray, instance: np.ndarray) -> tuple[np.ndarray, list[dict]]:
    """One image's panoptic PNG ((H, W, 3) uint8) and ``segments_info``.

    Segment ids are 1.. in order: thing segments (by instance, class), then stuff classes (by id).
    """
    table = class_table()
    cls = np.asarray(class_id, np.int64)
    ids = np.zeros(cls.shape, np.int64)
    info = []
    segs = thing_segments(class_id, instance)
    for c, _, mask in segs:
        ids[mask] = len(info) + 1
        info.append({"id": len(info) + 1, "category_id": c, "area": int(mask.sum()), "bbox": _box(mask),
                     "iscrowd": 0})
    thing = np.array([r.thing for r in table.rows], bool)
    for c in np.unique(cls):
        if c == 0 or thing[c]:
            continue
        mask = cls == c
        ids[mask] = len(info) + 1
        info.append({"id": len(info) + 1, "category_id": int(c), "area": int(mask.sum()), "bbox": _box(mask),
                     "iscrowd": 0})
    png = np.stack([ids % 256, ids // 256 % 256, ids // 65536], -1).astype(np.uint8)
    return png, info


def decode_panoptic(png: np.ndarray) -> np.ndarray:
    """(H, W) int64 segment ids of a panoptic PNG ((H, W, 3) uint8)."""
    p = np.asarray(png, np.int64)
    return p[..., 0] + 256 * p[..., 1] + 65536 * p[..., 2]
