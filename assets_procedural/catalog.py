"""One entry point for every asset family: ``build(kind, rng, **params)``.

The layout names what it needs by kind; this table maps the kind to its builder and to
the native class that identifies the object (instance boxes, statistics).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from assets_procedural.building import building
from assets_procedural.fence import fence
from assets_procedural.ground_pieces import driveway_apron, gravel_patch, median_strip, traffic_island, verge_crossing
from assets_procedural.motorcycles import motorcycle
from assets_procedural.person import person
from assets_procedural.proto_cache import CACHE
from assets_procedural.riders import bicyclist, motorcyclist, ridden
from assets_procedural.shelters import bus_shelter
from assets_procedural.shrubs import bush, hedge
from assets_procedural.street_furniture import lamp_post, traffic_light, traffic_sign
from assets_procedural.street_objects import advertising_column, bench, bike_rack, bollard, hydrant
from assets_procedural.street_objects import bin as litter_bin
from assets_procedural.tracks import rail_track, tram_rails
from assets_procedural.transit import bus, tram
from assets_procedural.two_wheelers import bicycle
from assets_procedural.utility_vehicles import box_van, construction_vehicle, trailer
from assets_procedural.vegetation import tree
from assets_procedural.vehicle import car, truck
from assets_procedural.walls import wall
from generator.geometry import Mesh
from generator.labels import class_table


def _ridden_vehicle(rider_kind: str, vehicle_class: str):
    """Builder of the two-wheeler a ``rider_kind`` rides: the vehicle of :func:`ridden` from the same
    generator state as the rider's own builder, its faces relabelled ``ridden_*`` (see classes.yaml)."""
    def build_vehicle(rng: np.random.Generator, **params) -> Mesh:
        _, vehicle = ridden(rider_kind, rng, **params)
        table = class_table()
        plain = table.id(vehicle_class.removeprefix("ridden_"))
        vehicle.face_class = np.where(vehicle.face_class == plain, table.id(vehicle_class), vehicle.face_class).astype(
            np.uint8)
        return vehicle
    return build_vehicle


BUILDERS: dict[str, Callable[..., Mesh]] = {
    "building": building,
    "tree": tree,
    "bush": bush,
    "hedge": hedge,
    "lamp_post": lamp_post,
    "traffic_light": traffic_light,
    "traffic_sign": traffic_sign,
    "fence": fence,
    "car": car,
    "truck": truck,
    "person": person,
    # issue 13: the rarer classes
    "bicycle": bicycle,
    "motorcycle": motorcycle,
    "bicyclist": bicyclist,
    "motorcyclist": motorcyclist,
    "ridden_bicycle": _ridden_vehicle("bicyclist", "ridden_bicycle"),
    "ridden_motorcycle": _ridden_vehicle("motorcyclist", "ridden_motorcycle"),
    "bus": bus,
    "tram": tram,
    "rail_track": rail_track,
    "tram_rails": tram_rails,
    "trailer": trailer,
    "box_van": box_van,
    "construction_vehicle": construction_vehicle,
    "wall": wall,
    "traffic_island": traffic_island,
    "median_strip": median_strip,
    "driveway_apron": driveway_apron,
    "verge_crossing": verge_crossing,
    "gravel_patch": gravel_patch,
    "bench": bench,
    "bin": litter_bin,
    "bollard": bollard,
    "bike_rack": bike_rack,
    "bus_shelter": bus_shelter,
    "hydrant": hydrant,
    "advertising_column": advertising_column,
}

KINDS: tuple[str, ...] = tuple(BUILDERS)

#: kind -> the native class name of the object's main part
MAIN_CLASS: dict[str, str] = {
    "building": "building",
    "tree": "tree_crown",
    "bush": "vegetation",
    "hedge": "vegetation",
    "lamp_post": "pole",
    "traffic_light": "traffic_light",
    "traffic_sign": "traffic_sign",
    "fence": "fence",
    "car": "car",
    "truck": "truck",
    "person": "person",
    "bicycle": "bicycle",
    "motorcycle": "motorcycle",
    "bicyclist": "bicyclist",
    "motorcyclist": "motorcyclist",
    "ridden_bicycle": "ridden_bicycle",
    "ridden_motorcycle": "ridden_motorcycle",
    "bus": "bus",
    "tram": "on_rails",
    "rail_track": "rail_track",
    "tram_rails": "road",
    "trailer": "other_vehicle",
    "box_van": "truck",
    "construction_vehicle": "other_vehicle",
    "wall": "wall",
    "traffic_island": "other_ground",
    "median_strip": "other_ground",
    "driveway_apron": "other_ground",
    "verge_crossing": "other_ground",
    "gravel_patch": "other_ground",
    "bench": "street_object",
    "bin": "street_object",
    "bollard": "street_object",
    "bike_rack": "street_object",
    "bus_shelter": "shelter",
    "hydrant": "street_object",
    "advertising_column": "street_object",
}


def build(kind: str, rng: np.random.Generator, **params) -> Mesh:
    """Build one asset of ``kind`` in its local frame.

    Parameters
    ----------
    kind : str
        One of :data:`KINDS`.
    rng : numpy.random.Generator
        The only source of randomness; the same state gives identical arrays.
    **params
        Forwarded to the family builder (e.g. ``height`` for trees, ``footprint`` for
        buildings); see each builder's docstring.

    Returns
    -------
    Mesh
        Built once per (kind, generator state, parameters) in a process and then shared
        (:mod:`assets_procedural.proto_cache`): its arrays are read-only.

    Raises
    ------
    KeyError
        For an unknown kind (the message lists the known ones).
    """
    try:
        builder = BUILDERS[kind]
    except KeyError:
        raise KeyError(f"unknown asset kind {kind!r}; known: {', '.join(KINDS)}") from None
    return CACHE.build(kind, rng, params, builder)
