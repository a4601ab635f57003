"""The moving fleet: box vans are a kind of their own, and ``traffic.counts`` sets exact numbers per scene."""

from __future__ import annotations

import collections

import pytest

from generator.layout import build_scene
from generator.spec.load import parse_spec
from generator.traffic.build import build_world
from generator.traffic.vehicles.fleet import drives, how_many


def _spec(traffic: dict):
    doc = {"name": "fleet_town", "seed": 5,
           "town": {"blocks_x": 2, "blocks_y": 2, "block_size_m": 50, "block_size_jitter_m": 6, "margin_m": 10},
           "density": {"moving_cars_per_100m": 0, "parked_cars_per_100m": 0, "people_per_100m": 0},
           "traffic": traffic}
    return parse_spec(doc, "fleet_town.json")


@pytest.fixture(scope="module")
def counted():
    spec = _spec({"cars_per_km": 40, "counts": {"cars": 7, "vans": 3, "buses": 1, "cyclists": 2, "pedestrians": 5}})
    scene = build_scene(spec)
    return spec, build_world(spec, scene, 2.0)


def test_counts_give_exactly_that_many_actors_of_each_kind(counted):
    _, world = counted
    kinds = collections.Counter(a.kind for a in world.actors)
    # cars: the count wins over the density (40/km would be far more on these lanes)
    assert kinds == {"car": 7, "box_van": 3, "bus": 1, "bicyclist": 2, "person": 5}


def test_vans_are_box_vans_of_class_truck_and_drive(counted):
    _, world = counted
    vans = [a for a in world.actors if a.kind == "box_van"]
    assert {a.cls for a in vans} == {"truck"}
    assert max(a.track.speed(1.5)[0] for a in vans) > 0.3


def test_a_count_overrides_its_density_and_a_kind_left_out_keeps_it():
    spec = _spec({"trucks_per_km": 2.0, "cars_per_km": 5.0, "counts": {"cars": 0}})
    assert how_many(spec.traffic, "cars_per_km", 10.0) == 0 and not drives(spec.traffic, "cars_per_km")
    assert how_many(spec.traffic, "trucks_per_km", 10.0) == 20 and drives(spec.traffic, "trucks_per_km")
    assert spec.traffic.enabled


def test_counts_alone_switch_traffic_on():
    assert _spec({"counts": {"pedestrians": 1}}).traffic.enabled
    assert not _spec({"counts": {"pedestrians": 0}}).traffic.enabled


def test_specs_without_vans_or_counts_keep_their_hash():
    plain = _spec({"cars_per_km": 5.0})
    assert _spec({"cars_per_km": 5.0, "vans_per_km": 0, "counts": None}).spec_hash == plain.spec_hash
    assert _spec({"cars_per_km": 5.0, "vans_per_km": 1}).spec_hash != plain.spec_hash
    assert _spec({"cars_per_km": 5.0, "counts": {"cars": 3}}).spec_hash != plain.spec_hash


def test_a_bad_count_is_one_line_naming_the_field():
    from generator.errors import SpecError

    with pytest.raises(SpecError, match=r"fleet_town.json: traffic.counts.cars"):
        _spec({"counts": {"cars": -1}})
    with pytest.raises(SpecError, match=r"traffic.counts"):
        _spec({"counts": {"lorries": 3}})


def test_the_seed002_preset_holds_seed_002s_actor_mix(root):
    from generator.spec import load_spec

    spec = load_spec(root / "scenes" / "seed002.json")
    c = spec.traffic.counts
    assert (c.cars, c.trucks, c.vans, c.buses, c.cyclists, c.motorcyclists, c.pedestrians + c.standing_pedestrians) == \
        (30, 10, 10, 10, 20, 20, 60)       # seed 002 sec. 4.1.1
    assert spec.town.redraw_every_frames is not None      # a new town per scene
    assert spec.labels.openlabel_min_points == 1          # every object that appears in the cloud
