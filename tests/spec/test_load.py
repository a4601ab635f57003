"""Scene specs and render configs: every shipped file loads; every kind of bad input is one clear error."""

from __future__ import annotations

import json

import pytest

from generator.errors import SpecError
from generator.spec import load_spec, parse_spec
from generator.spec.render import load_render_config
from generator.spec.validate import load_schema
from kits.paths import ROOT


@pytest.mark.parametrize("path", sorted((ROOT / "scenes").glob("*.json")), ids=lambda p: p.name)
def test_every_shipped_scene_loads(path):
    spec = load_spec(path)
    assert spec.name == path.stem
    assert len(spec.spec_hash) == 64


@pytest.mark.parametrize("path", sorted((ROOT / "render_configs").glob("*.yaml")), ids=lambda p: p.name)
def test_every_shipped_render_config_loads(path):
    cfg = load_render_config(path)
    assert cfg.name == path.stem


def test_paper_preset_is_seed003():
    cfg = load_render_config("paper")
    assert (cfg.resolution, cfg.samples, cfg.max_bounces) == ((1920, 1080), 24, 4)
    assert cfg.denoiser != "none"


def test_defaults_come_from_schema():
    spec = parse_spec({"name": "x", "seed": 1}, "x.json")
    schema = load_schema("scene")
    assert spec.town.blocks_x == schema["properties"]["town"]["properties"]["blocks_x"]["default"]
    assert spec.sensors.lidar.xyz_m == (0.0, 0.0, 1.73)


def test_hash_ignores_formatting_but_not_values():
    a = parse_spec({"name": "x", "seed": 1}, "a.json")
    b = parse_spec(json.loads('{"seed": 1,   "name": "x", "town": {"blocks_x": 3}}'), "b.json")
    c = parse_spec({"name": "x", "seed": 2}, "c.json")
    assert a.spec_hash == b.spec_hash != c.spec_hash


BAD = [
    ({"town": {"blocks_x": -2}}, "town.blocks_x: must be an integer in [1, 12], got -2"),
    ({"town": {"blocks_x": 2.5}}, "town.blocks_x: must be an integer in [1, 12], got 2.5"),
    ({"town": {"blocks_x": True}}, "town.blocks_x: must be an integer in [1, 12], got true"),
    ({"twon": {}}, "twon: unknown key"),
    ({"town": {"block_szie_m": 3}}, "town.block_szie_m: unknown key"),
    ({"seed": "a"}, "seed: must be an integer >= 0, got \"a\""),
    ({"name": "../../etc"}, "name: must be a string matching"),
    ({"heights": {"tree_m": [9, 3]}}, "heights.tree_m: must be a range [low, high] with low <= high, got [9, 3]"),
    ({"heights": {"tree_m": [9]}}, "heights.tree_m: must be a list of 2 items"),
    ({"density": {"buildings": 1.5}}, "density.buildings: must be a number in [0, 1], got 1.5"),
    ({"lidar": {"intensity_model": "foo"}}, "lidar.intensity_model: must be one of"),
    ({"town": 5}, "town: must be an object, got 5"),
    ({"paths": {"speed_mps": 0}}, "paths.speed_mps: must be a number in (0, 40]"),
    # the newer street families (issue 13) and the stereo stream (issue 15)
    ({"density": {"riders_per_km": -1}}, "density.riders_per_km: must be a number in [0, 200], got -1"),
    ({"density": {"trams": 1.5}}, "density.trams: must be an integer in [0, 20], got 1.5"),
    ({"density": {"walls": 2}}, "density.walls: must be a number in [0, 1], got 2"),
    ({"density": {"street_objects_per_100m": "many"}}, "density.street_objects_per_100m: must be a number"),
    ({"sensors": {"stereo": {"baseline_m": 0}}}, "sensors.stereo.baseline_m: must be a number in [0.05, 2.0], got 0"),
    ({"sensors": {"stereo": {"every": 0}}}, "sensors.stereo.every: must be an integer in [1, 1000], got 0"),
    # asset variety (issue 29)
    ({"assets": {"variants": {"car": 0}}}, "assets.variants.car: must be an integer in [1, 1000], got 0"),
    ({"assets": {"variants": {"people": 4}}}, "assets.variants.people: unknown key"),
    ({"assets": {"redraw_every_towns": 0}}, "assets.redraw_every_towns: must be"),
    ({"assets": {"child_share": 1.5}}, "assets.child_share: must be a number in [0, 1], got 1.5"),
]


@pytest.mark.parametrize("patch,expected", BAD, ids=[b[1].split(":")[0] for b in BAD])
def test_bad_values_name_file_field_and_reason(patch, expected):
    doc = {"name": "x", "seed": 1, **patch}
    with pytest.raises(SpecError) as e:
        parse_spec(doc, "scenes/x.json")
    assert str(e.value).startswith("scenes/x.json: " + expected.split(":")[0] + ":")
    assert expected in str(e.value)
    assert "\n" not in str(e.value)


def test_missing_required_key():
    with pytest.raises(SpecError, match=r"^x.json: seed: is required$"):
        parse_spec({"name": "x"}, "x.json")


def test_missing_file(tmp_path):
    with pytest.raises(SpecError, match="nope.json: file not found"):
        load_spec(tmp_path / "nope.json")


@pytest.mark.parametrize("text,expected", [
    ('{"name": "x", "seed": 1,}', "invalid JSON at line 1"),
    ('{"name": "x", "seed": NaN}', "invalid JSON"),
    ('{"name": "x", "name": "y", "seed": 1}', "duplicate key 'name'"),
    ('[1, 2]', "(top level): must be a JSON object"),
])
def test_malformed_json(tmp_path, text, expected):
    p = tmp_path / "bad.json"
    p.write_text(text)
    with pytest.raises(SpecError) as e:
        load_spec(p)
    assert expected in str(e.value)


def test_yaml_is_parsed_safely(tmp_path):
    p = tmp_path / "evil.yaml"
    p.write_text("name: !!python/object/apply:os.system ['echo pwned']\nresolution: [8, 8]\nsamples: 1\n")
    with pytest.raises(SpecError, match="invalid YAML"):
        load_render_config(p)


def test_render_config_errors(tmp_path):
    p = tmp_path / "r.yaml"
    p.write_text("name: r\nresolution: [640]\nsamples: 4\n")
    with pytest.raises(SpecError, match=r"r.yaml: resolution: must be a list of 2 items"):
        load_render_config(p)
    p.write_text("name: r\nresolution: [64, 64]\nsamples: 4\ndenoiser: optics\n")
    with pytest.raises(SpecError, match=r"denoiser: must be one of"):
        load_render_config(p)


def test_asset_variety_counts_in_the_hash_only_when_not_the_default():
    plain = parse_spec({"name": "x", "seed": 1}, "x.json")
    assert plain.assets.variants.car == 48 and plain.assets.variants.person == 48
    assert parse_spec({"name": "x", "seed": 1, "assets": {"variants": {"car": 48}}}, "x.json").spec_hash == \
        plain.spec_hash
    assert parse_spec({"name": "x", "seed": 1, "assets": {"variants": {"car": 6}}}, "x.json").spec_hash != \
        plain.spec_hash
