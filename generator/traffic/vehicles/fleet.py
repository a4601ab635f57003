"""The prototypes of the moving fleet: the same asset families as the static town, posed to drive.

Vehicles of the moving traffic come from the scene's asset :class:`~generator.layout.placement.prototypes.Library`
(kinds of :data:`KINDS`), with two differences from parked ones:

* a ridden two-wheeler is the rider and the vehicle merged into one prototype (one instance, as
  SemanticKITTI labels a bicyclist with its bicycle);
* an excavator drives with its house slewed straight over the tracks (``slew_deg`` 0), as a real one
  travels. Parked excavators keep their drawn slew of up to 30 degrees, which makes their box 3-6 m
  wide; on a 3.5 m lane such a box reaches over the lane line into the parking strip and the
  opposite lane (the cause of moving excavators grazing parked cars). Travelling straight, the box
  is as wide as the tracks or the house (2.6-2.9 m), inside the band
  :func:`generator.traffic.lanes.clearance.blocked_lanes` keeps free of static objects. These variants are a
  separate family (tag ``"travel"``, stream ``("assets", "construction_vehicle", "travel", i)``), so
  the static town's excavators do not change.
"""

from __future__ import annotations

import numpy as np

from generator.geometry.mesh import merge
from generator.layout.placement.prototypes import Library, Proto
from generator.layout.placement.variety import car_variant

#: kind -> (tag, parameters) of the variant family that drives (kinds not listed: the plain variants)
TRAVEL_POSE = {"construction_vehicle": ("travel", {"slew_deg": 0.0})}

# spec field -> (asset kind, variants, speed factor of the limit, max acceleration m/s^2, nominal length m);
# the variants are the default: a library with the spec's ``assets.variants`` has its own count (:func:`n_variants`)
KINDS = {
    "cars_per_km": ("car", 6, (0.8, 1.0), 2.0, 4.6),
    "trucks_per_km": ("truck", 3, (0.7, 0.85), 1.2, 8.0),
    "buses_per_km": ("bus", 4, (0.7, 0.85), 1.0, 12.0),
    "other_vehicles_per_km": ("construction_vehicle", 4, (0.5, 0.7), 1.0, 7.0),
    "cyclists_per_km": ("bicyclist", 4, (0.35, 0.55), 1.0, 1.8),
    "motorcyclists_per_km": ("motorcyclist", 4, (0.8, 1.0), 2.5, 2.2),
    # last, so towns without vans draw every other vehicle as before
    "vans_per_km": ("box_van", 3, (0.75, 0.9), 1.5, 6.6),
}


def n_variants(lib: Library, kind: str, default: int) -> int:
    """Variants of moving ``kind`` in ``lib`` (the spec's ``assets.variants``, else the :data:`KINDS` default)."""
    return lib.count(kind, default)


def how_many(traffic, field_name: str, extent: float) -> int:
    """Actors of the kind of density ``field_name`` (``"cars_per_km"``, ``"pedestrians_per_100m"``...) in a
    scene of ``extent`` (km of lane, or hundreds of metres of sidewalk): ``traffic.counts`` when it names
    the kind (exact per scene, as seed 002 loads its scenes), else the density times the extent."""
    n = getattr(traffic.counts, field_name.rsplit("_per_", 1)[0], None) if traffic.counts is not None else None
    return int(n) if n is not None else round(getattr(traffic, field_name) * extent)


def drives(traffic, field_name: str) -> bool:
    """Whether the kind of density ``field_name`` may appear at all (a count or a density above 0)."""
    n = getattr(traffic.counts, field_name.rsplit("_per_", 1)[0], None) if traffic.counts is not None else None
    return n > 0 if n is not None else getattr(traffic, field_name) > 0


def fleet_proto(lib: Library, kind: str, i: int) -> Proto:
    """Prototype ``i`` of a moving vehicle kind (see the module docstring).

    Parameters
    ----------
    lib : Library
    kind : str
        Asset kind (``"car"``, ``"bicyclist"``, ``"construction_vehicle"`` ...).
    i : int
        Variant number.

    Returns
    -------
    Proto
        Mesh in the local frame (x forward, y left, z up, origin on the ground), with its bounds.
    """
    if kind in TRAVEL_POSE:
        tag, params = TRAVEL_POSE[kind]
        return lib.variant(kind, i, lambda g: dict(params), tag=tag)
    if kind == "car":       # the body type of its place in the library (as the parked cars)
        return car_variant(lib, i)
    if kind not in ("bicyclist", "motorcyclist"):
        return lib.variant(kind, i)
    key = f"{kind}_riding_v{i}"
    if key not in lib.protos:
        rider = lib.variant(kind, i, lambda g: {"with_vehicle": False})
        vehicle = lib.variant("ridden_bicycle" if kind == "bicyclist" else "ridden_motorcycle", i, stream_kind=kind)
        mesh = merge([vehicle.mesh, rider.mesh])
        lo, hi = mesh.bounds()
        lib.protos[key] = Proto(key, kind, mesh, lo, hi, np.zeros((0, 6)))
    return lib.protos[key]


def widest_half_width(spec, lib: Library, kinds: dict, ego_width: float) -> tuple[float, str]:
    """Half width (metres, mirrors included) of the widest vehicle the traffic of ``spec`` may
    drive, and its prototype key.

    Parameters
    ----------
    spec : generator.spec.SceneSpec
        ``spec.traffic`` densities: kinds at 0 drive nowhere.
    lib : Library
        The asset library the traffic draws its prototypes from.
    kinds : dict
        :data:`KINDS` (spec field -> (kind, variants, ...)).
    ego_width : float
        Width of the ego's box, metres.
    """
    best, key = ego_width / 2, "ego"
    for field_name, (kind, n_var, *_rest) in kinds.items():
        if not drives(spec.traffic, field_name):
            continue
        for i in range(n_variants(lib, kind, n_var)):
            proto = fleet_proto(lib, kind, i)
            half = float(proto.hi[1] - proto.lo[1]) / 2     # the box is centred on the lane centre line
            if half > best:
                best, key = half, proto.key
    return best, key
