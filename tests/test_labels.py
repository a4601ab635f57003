"""The one class table and every label set derived from it."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from generator.labels import class_table
from generator.materials import material_table

T = class_table()
# DESIGN.md's table: native -> (SemanticKITTI raw id, unified-11 name, Cityscapes id)
EXPECTED = {
    "unlabeled": (0, "unlabeled", 0), "road": (40, "road", 7), "road_marking": (60, "road", 7),
    "crosswalk": (60, "road", 7), "curb": (48, "sidewalk", 8), "sidewalk": (48, "sidewalk", 8),
    "parking": (44, "other-ground", 9), "terrain": (72, "terrain", 22), "building": (50, "building", 11),
    "fence": (51, "fence", 13), "vegetation": (70, "vegetation", 21), "tree_trunk": (71, "vegetation", 21),
    "tree_crown": (70, "vegetation", 21), "pole": (80, "pole", 17), "traffic_light": (81, "traffic-sign", 19),
    "traffic_sign": (81, "traffic-sign", 20), "car": (10, "vehicle", 26), "truck": (18, "vehicle", 27),
    "person": (30, "person", 24), "sky": (0, "unlabeled", 23),
    # issue 13: the rarer classes (judgement calls explained in classes.yaml)
    "bicycle": (11, "vehicle", 33), "motorcycle": (15, "vehicle", 32), "bus": (13, "vehicle", 28),
    "on_rails": (16, "vehicle", 31), "other_vehicle": (20, "vehicle", 30), "bicyclist": (31, "person", 25),
    "motorcyclist": (32, "person", 25), "wall": (51, "fence", 12), "other_ground": (49, "other-ground", 6),
    "street_object": (99, "unlabeled", 4), "rail_track": (49, "other-ground", 10), "shelter": (52, "unlabeled", 11),
    # a ridden two-wheeler: SemanticKITTI counts it with its rider, Cityscapes as the vehicle
    "ridden_bicycle": (31, "person", 33), "ridden_motorcycle": (32, "person", 32),
}
#: classes SemanticKITTI and Cityscapes give instance ids
THINGS = {"car", "truck", "person", "bicycle", "motorcycle", "bus", "on_rails", "other_vehicle", "bicyclist",
          "motorcyclist", "ridden_bicycle", "ridden_motorcycle"}


def test_every_native_class_maps_everywhere():
    assert set(T.names) == set(EXPECTED)
    for name, (raw, uni, cs) in EXPECTED.items():
        i = T.id(name)
        assert int(T.to_semantickitti[i]) == raw, name
        assert T.unified_names[int(T.to_unified[i])] == uni, name
        assert int(T.to_cityscapes[i]) == cs, name


def test_semantickitti_ids_exist_in_the_reference_config(root):
    packaged = yaml.safe_load((root / "generator/labels/semantic-kitti.yaml").read_text())
    assert set(int(v) for v in T.to_semantickitti) <= set(int(k) for k in packaged["labels"])
    assert not T.lidar_returns[T.id("sky")] and T.lidar_returns[T.id("road")]


def test_every_semantickitti_id_maps_to_unified11():
    assert set(T.sk_labels) <= set(T.sk_to_unified_map)
    assert set(T.unified_names) == set(range(12))


def test_inverse_maps_round_trip():
    for raw in set(int(v) for v in T.to_semantickitti):
        assert int(T.to_semantickitti[T.from_semantickitti(raw)]) == raw
    for uni, raw in T.unified_to_sk_map.items():
        assert int(T.sk_to_unified[raw]) == uni
    with pytest.raises(KeyError):
        T.from_semantickitti(1)  # outlier: no native class


def test_first_twenty_ids_are_unchanged_and_things_are_vehicles_and_people():
    assert T.names[:20] == ["unlabeled", "road", "road_marking", "crosswalk", "curb", "sidewalk", "parking", "terrain",
                            "building", "fence", "vegetation", "tree_trunk", "tree_crown", "pole", "traffic_light",
                            "traffic_sign", "car", "truck", "person", "sky"]
    assert {r.name for r in T.rows if r.thing} == THINGS


def test_seed003_names_are_table_one_rows():
    assert set(T.seed003_names()) == {
        "Buildings", "Road", "Curb", "Cars", "Sky", "Trees", "Poles", "Void", "Road marking", "Crosswalk",
        "Traffic lights", "Vegetation horizontal", "Vegetation vertical", "Road signs"}


def test_hull_policy_and_colours():
    assert {T.names[i] for i in np.flatnonzero(T.hull_classes)} == {"fence", "vegetation", "tree_crown"}
    assert T.colors.shape == (len(T), 3) and T.colors.dtype == np.uint8
    assert len({tuple(c) for c in T.colors}) == len(T), "every class needs its own preview colour"


def test_material_table():
    m = material_table()
    assert m.names[0] == "default" and len(set(m.names)) == len(m)
    assert ((m.reflectivity >= 0) & (m.reflectivity <= 1)).all()
    assert m.retro[m.id("sign_face")] and not m.retro[m.id("asphalt")]
