"""The one class table and every label set derived from it."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from generator.labels import class_table
from generator.materials import material_table

T = class_table()
# The class table (generator/labels/classes.yaml): native -> (SemanticKITTI raw id, unified-11 name, Cityscapes id)
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
    # only a building's facade glass has a room behind it; a vehicle's glass and free panes go on
    assert [m.names[i] for i in np.flatnonzero(m.room_behind)] == ["window_glass", "shop_glass"]
    assert (m.transmittance[m.room_behind] > 0).all()


def test_a_room_behind_an_opaque_material_is_refused():
    from generator.materials import MaterialInfo, MaterialTable

    with pytest.raises(ValueError, match="plaster.behind must be 'room' on a glass material"):
        MaterialTable([MaterialInfo(0, "plaster", 0.5, False, (1, 1, 1), None, 0.0, "room")])


# -- moving actors: SemanticKITTI's moving-* raw ids ---------------------------------------------------------
#: native class -> its moving raw id (reference semantic-kitti.yaml); every other class keeps its static id
MOVING = {"car": 252, "bicyclist": 253, "ridden_bicycle": 253, "person": 254, "motorcyclist": 255,
          "ridden_motorcycle": 255, "on_rails": 256, "bus": 257, "truck": 258, "other_vehicle": 259}


def learning_map_of(raw, learning):
    return np.array([learning[int(r)] for r in raw])


def test_moving_ids_are_the_reference_ones_and_learn_as_their_static_class():
    learning = {int(k): int(v) for k, v in T.sk_config["learning_map"].items()}
    for i, name in enumerate(T.names):
        raw = int(T.to_semantickitti_moving[i])
        assert raw == MOVING.get(name, int(T.to_semantickitti[i])), name
        assert learning[raw] == learning[int(T.to_semantickitti[i])], name
        assert T.sk_to_unified[raw] == T.to_unified[i], name
    from generator.labels.sets import label_sets, semantickitti_to_unified

    raw = np.array(sorted(set(MOVING.values())), np.uint16)  # what evaluate / convert read
    assert np.array_equal(label_sets()["semantickitti"].from_raw[raw], learning_map_of(raw, learning))
    assert semantickitti_to_unified(raw).tolist() == [1, 2, 2, 2, 1, 1, 1, 1]
    assert {T.sk_labels[r] for r in MOVING.values()} == {f"moving-{n}" for n in (
        "car", "bicyclist", "person", "motorcyclist", "on-rails", "bus", "truck", "other-vehicle")}


def test_semantickitti_labels_use_moving_ids_only_where_moving():
    from generator.labels.sets import semantickitti_labels

    native = np.array([T.id(n) for n in ("car", "car", "road", "person", "bicycle", "unlabeled", "truck")])
    moving = np.array([1, 0, 1, 1, 1, 1, 1], np.uint8)
    raw = semantickitti_labels(native, moving)
    assert raw.dtype == np.uint16 and raw.tolist() == [252, 10, 40, 254, 11, 0, 258]
    assert semantickitti_labels(native).tolist() == T.to_semantickitti[native].tolist()


def test_moving_ids_read_back_as_their_native_class():
    for raw in MOVING.values():
        assert int(T.to_semantickitti_moving[T.from_semantickitti(raw)]) == raw
    assert T.from_semantickitti(252) == T.id("car") and T.from_semantickitti(253) == T.id("bicyclist")


def test_bad_moving_table_is_refused():
    from generator.labels.registry import ClassTable

    with pytest.raises(ValueError, match="learning"):
        ClassTable(T.rows, T.sk_config, {"classes": T.unified_names, "from_semantickitti": T.sk_to_unified_map,
                                         "to_semantickitti": T.unified_to_sk_map}, moving={"person": 252})
    with pytest.raises(ValueError, match="moving-"):
        ClassTable(T.rows, T.sk_config, {"classes": T.unified_names, "from_semantickitti": T.sk_to_unified_map,
                                         "to_semantickitti": T.unified_to_sk_map}, moving={"car": 10})


def test_dataset_label_config_carries_the_moving_ids_the_api_remaps(tmp_path):
    """semantic-kitti-api builds its remap LUT from ``learning_map`` keys (``evaluate_semantics.py``)."""
    from generator.formats.label_config import write_label_config

    path = tmp_path / "semantic-kitti.yaml"
    write_label_config(path, {10: 3, 252: 1, 40: 4}, {"valid": [0]})
    cfg = yaml.safe_load(path.read_text())
    for section in ("labels", "color_map", "learning_map", "content"):
        assert set(MOVING.values()) <= set(cfg[section]), section
    assert cfg["content"][252] == 1 / 8
    keys = np.array(list(cfg["learning_map"].keys()))
    lut = np.zeros(keys.max() + 100, np.int32)
    lut[keys] = list(cfg["learning_map"].values())
    assert lut[np.array([252, 10, 254, 30, 258, 18])].tolist() == [1, 1, 6, 6, 4, 4]
