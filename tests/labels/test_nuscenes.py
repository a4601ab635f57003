"""The nuScenes and COCO views of the class table: complete, and what the reference tools define."""

from __future__ import annotations

import pytest

from generator.labels import class_table
from generator.labels.coco import coco_categories
from generator.labels.detection import detection_classes
from generator.labels.nuscenes import ATTRIBUTES, SEED002_CLASSES, nuscenes_labels, visibility_token


def test_every_box_class_has_a_nuscenes_category_the_devkit_folds_as_we_do():
    pytest.importorskip("nuscenes")
    from nuscenes.eval.detection.constants import ATTRIBUTE_NAMES, DETECTION_NAMES
    from nuscenes.eval.detection.utils import category_to_detection_name

    labels = nuscenes_labels()
    assert set(labels.boxes) == set(detection_classes().boxes)
    for category in labels.categories:
        assert labels.detection.get(category) == category_to_detection_name(category), category
    assert set(labels.detection.values()) == set(DETECTION_NAMES) >= set(SEED002_CLASSES)
    assert set(ATTRIBUTES) == set(ATTRIBUTE_NAMES)


def test_the_classes_seed_002_scores_come_out_of_the_box_classes():
    labels = nuscenes_labels()
    assert {labels.detection_class(c) for c in labels.boxes} >= set(SEED002_CLASSES)
    assert labels.detection_class("bicyclist") == "bicycle"           # a ridden bicycle: one bicycle box
    assert labels.detection_class("truck", "box_van") == "truck"      # seed 002's vans count as trucks
    assert labels.detection_class("other_vehicle", "trailer") == "trailer"


@pytest.mark.parametrize("fraction, token", [(0.0, "1"), (0.39, "1"), (0.4, "2"), (0.6, "3"), (0.8, "4"), (1.0, "4")])
def test_visibility_bins(fraction, token):
    assert visibility_token(fraction) == token


def test_coco_categories_are_the_native_classes_with_their_thing_flag():
    cats = coco_categories()
    rows = {r.id: r for r in class_table().rows}
    assert [c["id"] for c in cats] == sorted(rows)[1:]             # every class but unlabeled (void)
    assert all(c["name"] == rows[c["id"]].name and c["isthing"] == int(rows[c["id"]].thing) for c in cats)
