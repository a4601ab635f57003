"""Label sets of predictions: Cityscapes' own table, seed 001's merge as data, which sets a prediction determines."""

from __future__ import annotations

import numpy as np
import pytest

from generator.errors import SpecError
from generator.formats import cityscapes as cs
from generator.labels import class_table
from generator.labels.class_sets import (
    builtin_sets,
    cityscapes_table,
    compatible_sets,
    load_class_set,
    parse_class_set,
    semantickitti_raw,
    translate,
)

T = class_table()


def test_cityscapes_table_is_cityscapesscripts_own():
    labels = pytest.importorskip("cityscapesscripts.helpers.labels")
    theirs = {lb.id: (lb.name, lb.trainId) for lb in labels.labels if lb.id >= 0}
    t = cityscapes_table()
    assert {i: (t["names"][i], int(t["train"][i])) for i in range(34)} == theirs
    assert {i: (row[0], row[1]) for i, row in cs.LABELS.items()} == theirs  # the export's table agrees


def test_seed001_merge_is_cityscapes_categories_over_all_34_ids():
    labels = pytest.importorskip("cityscapesscripts.helpers.labels")
    seed = builtin_sets()["seed001"]
    assert len(seed.names) == 8
    for lb in labels.labels:
        if lb.id >= 0:
            assert seed.names[int(seed.from_base[lb.id])] == lb.category, lb.name


def test_cityscapes_evaluates_the_19_train_classes():
    s = builtin_sets()["cityscapes"]
    assert s.size == 34 and 34 - len(s.ignore) == 19
    tr = builtin_sets()["cityscapes_trainids"]
    assert translate(tr, s)[13] == 26 and translate(tr, s)[255] == 0  # car; void -> unlabeled


def test_a_prediction_is_scored_only_in_sets_it_determines():
    sets = builtin_sets()
    # Cityscapes vegetation is native vegetation, tree_trunk or tree_crown: it cannot say which
    assert set(compatible_sets(sets["cityscapes"])) == {"cityscapes", "seed001"}
    assert set(compatible_sets(sets["native"])) == {"native", "cityscapes", "seed001", "unified11", "semantickitti"}
    # unified11 merges trunk into vegetation and riders into person, but a Cityscapes motorcycle is a
    # native motorcycle (vehicle) or a ridden one (motorcyclist: person): still undetermined
    assert translate(sets["cityscapes"], sets["unified11"]) is None
    # a merged class maps to its merge; a class no native class is (bridge) goes to ignored
    lut = translate(sets["cityscapes"], sets["seed001"])
    assert [sets["seed001"].names[int(lut[i])] for i in (7, 10, 15, 25, 31)] == \
        ["flat", "flat", "construction", "human", "vehicle"]
    assert translate(sets["native"], sets["cityscapes"])[T.id("shelter")] == 11  # building


def test_semantickitti_ids_of_predictions():
    sets = builtin_sets()
    assert semantickitti_raw(sets["native"]).tolist() == T.to_semantickitti.tolist()
    raw = semantickitti_raw(sets["cityscapes"])
    assert raw[21] == 70 and raw[26] == 10 and raw[23] == 0 and raw[25] == 31
    assert semantickitti_raw(sets["seed001"]).tolist() == [0, 40, 50, 80, 70, 0, 30, 10]


def test_a_user_label_set_file(tmp_path):
    f = tmp_path / "mymodel.yaml"
    f.write_text("base: cityscapes\nignore: [0]\nclasses:\n"
                 "  0: {name: void}\n  1: {name: ground, members: [road, sidewalk, parking]}\n"
                 "  2: {name: car, members: [26]}\n")
    s = load_class_set(str(f))
    assert s.name == "mymodel" and s.size == 3
    assert s.from_base[7] == 1 and s.from_base[9] == 1 and s.from_base[26] == 2 and s.from_base[11] == 0
    # ground = road + sidewalk (+ parking, unscored in Cityscapes): Cityscapes splits it, seed001 (flat) does not
    assert set(compatible_sets(s)) == {"seed001"}


@pytest.mark.parametrize("body, field", [
    ("base: cityscapes\nignore: [0]\nclasses: {0: {name: void}, 1: {name: x, members: []}}\n", "classes"),
    ("base: cityscapes\nignore: [0]\nclasses: {0: {name: void}, 1: {name: x, members: [roadd]}}\n",
     "classes.1.members[0]"),
    ("base: cityscapes\nignore: [0]\nclasses: {0: {name: v}, 1: {name: x, members: [7]}, 2: {name: y, members: [7]}}\n",
     "classes.2.members[0]"),
    ("base: kitti\nignore: [0]\nclasses: {0: {name: v}}\n", "base"),
    ("base: native\nignore: [9]\nclasses: {0: {name: v}, 1: {name: car, members: [car]}}\n", "ignore"),
])
def test_bad_label_set_files_name_file_and_field(tmp_path, body, field):
    f = tmp_path / "bad.yaml"
    f.write_text(body)
    with pytest.raises(SpecError) as e:
        load_class_set(str(f))
    assert str(e.value).startswith(f"{f}: {field}: ")
    if field == "classes":
        assert "maps to nothing" in str(e.value)


def test_unknown_label_set_name():
    with pytest.raises(SpecError, match="neither a label set"):
        load_class_set("kitti")
    with pytest.raises(SpecError):
        parse_class_set([1, 2], "x.yaml")
    assert np.array_equal(builtin_sets()["native"].from_native, np.arange(len(T)))
