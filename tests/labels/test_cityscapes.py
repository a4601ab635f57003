"""Cityscapes' label table is data (generator/labels/cityscapes.yaml) that the class table maps into."""

from __future__ import annotations

from generator.labels import class_table
from generator.labels.cityscapes import cityscapes_labels


def test_every_native_class_maps_to_a_cityscapes_label():
    table = cityscapes_labels().table
    assert set(class_table().to_cityscapes.tolist()) <= set(table)


def test_the_nineteen_train_classes_in_train_id_order():
    cs = cityscapes_labels()
    train = cs.train_classes
    assert len(train) == 19 and [cs.table[i][1] for i, _ in train] == list(range(19))
    assert train[0] == (7, "road") and train[-1] == (33, "bicycle")


def test_instance_classes_are_cityscapes_things():
    names = {cityscapes_labels().table[i][0] for i in cityscapes_labels().instance_ids}
    assert names == {"person", "rider", "car", "truck", "bus", "caravan", "trailer", "train", "motorcycle", "bicycle"}
