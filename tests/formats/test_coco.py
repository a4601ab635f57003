"""COCO records of class and instance maps (pure): thing segments, RLE, panoptic ids."""

from __future__ import annotations

import numpy as np
import pytest

from generator.formats import coco as C
from generator.labels import class_table

pytest.importorskip("pycocotools")
T = class_table()


def _maps():
    cls = np.full((20, 30), T.id("road"), np.uint8)
    inst = np.zeros((20, 30), np.uint32)
    cls[:5] = T.id("sky")
    cls[0, 0] = 0                                          # one unlabeled pixel: void
    cls[8:14, 2:10], inst[8:14, 2:10] = T.id("car"), 5
    cls[6:10, 20:24], inst[6:10, 20:24] = T.id("bicyclist"), 9                 # a moving cyclist: one actor,
    cls[10:16, 19:26], inst[10:16, 19:26] = T.id("ridden_bicycle"), 9          # rider and bicycle classes
    return cls, inst


def test_a_rider_and_its_bicycle_are_two_segments_of_one_instance():
    cls, inst = _maps()
    segs = C.thing_segments(cls, inst)
    assert [(c, i) for c, i, _ in segs] == [(T.id("car"), 5), (T.id("bicyclist"), 9), (T.id("ridden_bicycle"), 9)]
    assert [int(m.sum()) for _, _, m in segs] == [48, 16, 42]


def test_rle_bbox_and_area_round_trip_through_pycocotools():
    from pycocotools import mask as M

    cls, inst = _maps()
    anns = C.instance_annotations(3, cls, inst, 10)
    assert [a["id"] for a in anns] == [10, 11, 12] and {a["image_id"] for a in anns} == {3}
    for a, (_, _, m) in zip(anns, C.thing_segments(cls, inst), strict=True):
        rle = {"size": a["segmentation"]["size"], "counts": a["segmentation"]["counts"].encode()}
        assert np.array_equal(M.decode(rle).astype(bool), m)
        assert a["area"] == int(M.area(rle)) and a["bbox"] == M.toBbox(rle).tolist()
    assert anns[0]["bbox"] == [2.0, 8.0, 8.0, 6.0]        # x, y, w, h in pixels from the top-left corner


def test_panoptic_covers_every_labelled_pixel_once_and_leaves_unlabeled_void():
    cls, inst = _maps()
    png, info = C.panoptic(cls, inst)
    ids = C.decode_panoptic(png)
    assert ids[0, 0] == 0 and (ids[cls != 0] > 0).all()
    assert sorted(int(i) for i in np.unique(ids) if i) == [s["id"] for s in info]
    for s in info:
        m = ids == s["id"]
        assert s["area"] == int(m.sum()) and len(np.unique(cls[m])) == 1 and s["category_id"] == int(cls[m][0])
    stuff = [s["category_id"] for s in info if not T.rows[s["category_id"]].thing]
    assert sorted(stuff) == sorted([T.id("road"), T.id("sky")])     # one segment per stuff class
