"""Specs of the small street-variety towns several test modules build (one-way, every street kind)."""

from __future__ import annotations

from generator.spec import parse_spec

#: the traffic of the full-mix towns: every kind of vehicle and some walkers
MIX_TRAFFIC = {"cars_per_km": 25, "trucks_per_km": 2, "buses_per_km": 1, "cyclists_per_km": 3,
               "motorcyclists_per_km": 2, "pedestrians_per_100m": 1.0}


def one_way_spec(seed: int, lanes: int = 1, blocks=(3, 3), traffic: dict | None = None, **types):
    """A small town whose streets are drawn from ``types`` (default: plain 1 : one-way 3)."""
    doc = {"name": "one_way_town", "seed": seed,
           "town": {"blocks_x": blocks[0], "blocks_y": blocks[1], "block_size_m": 40, "block_size_jitter_m": 8,
                    "margin_m": 10, "lanes_per_direction": lanes},
           "streets": {"types": types or {"plain": 1, "one_way": 3}}}
    if traffic is not None:
        doc["traffic"] = traffic
        doc["density"] = {"moving_cars_per_100m": 0}
    return parse_spec(doc, "one_way_town.json")


def full_spec(seed: int, traffic: dict | None = None, one_way: float = 3):
    """A 4 x 4 town with every street kind: one-way, shared, roundabouts and closed streets."""
    doc = {"name": "full_mix_town", "seed": seed,
           "town": {"blocks_x": 4, "blocks_y": 4, "block_size_m": 40, "block_size_jitter_m": 6, "margin_m": 10},
           "density": {"moving_cars_per_100m": 0, "people_per_100m": 3},
           "streets": {"types": {"plain": 1, "residential": 1, "shared": 1, "one_way": one_way}, "roundabouts": 0.3,
                       "closed_streets": 0.3}}
    if traffic is not None:
        doc["traffic"] = traffic
    return parse_spec(doc, "full_mix_town.json")


def skewed_spec(angle=(65.0, 65.0), seed: int = 4, traffic: dict | None = None, speed_mps: float | None = None,
                **streets):
    """A 2 x 2 town whose streets cross at an angle drawn from ``angle`` (degrees), with every street
    type and the things that stand by streets; ``streets``: more ``streets`` fields."""
    doc = {"name": "skewed_town", "seed": seed,
           "town": {"blocks_x": 2, "blocks_y": 2, "block_size_m": 50, "block_size_jitter_m": 6, "margin_m": 10},
           "streets": {"intersection_angle_deg": list(angle),
                       "types": {"plain": 2, "residential": 1, "boulevard": 1, "arterial": 1}, **streets},
           "density": {"bike_racks_per_block": 2, "street_objects_per_100m": 4, "riders_per_km": 20,
                       "bus_stops_per_km": 4, "walls": 0.5, "driveways": 0.5, "gravel": 0.5, "trams": 1}}
    if traffic is not None:
        doc["traffic"] = traffic
    if speed_mps is not None:
        doc["paths"] = {"speed_mps": speed_mps}
    return parse_spec(doc, "skewed_town.json")


def roundabout_spec(blocks: int = 2, share: float = 1.0, seed: int = 11, traffic: dict | None = None, **town):
    """A ``blocks`` x ``blocks`` town, ``share`` of its interior nodes roundabouts; ``town``: more town fields."""
    doc = {"name": "roundabout_town", "seed": seed,
           "town": {"blocks_x": blocks, "blocks_y": blocks, "block_size_m": 45, "block_size_jitter_m": 6,
                    "margin_m": 10, **town},
           "density": {"moving_cars_per_100m": 0}, "streets": {"roundabouts": share}}
    if traffic is not None:
        doc["traffic"] = traffic
    return parse_spec(doc, "roundabout_town.json")
