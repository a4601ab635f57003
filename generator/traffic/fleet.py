"""The prototypes of the moving fleet: the same asset families as the static town, posed to drive.

Vehicles of the moving traffic come from the scene's asset :class:`~generator.layout.placement_core.Library`
(kinds of :data:`KINDS`), with two differences from parked ones:

* a ridden two-wheeler is the rider and the vehicle merged into one prototype (one instance, as
  SemanticKITTI labels a bicyclist with its bicycle);
* an excavator drives with its house slewed straight over the tracks (``slew_deg`` 0), as a real one
  travels. Parked excavators keep their drawn slew of up to 30 degrees, which makes their box 3-6 m
  wide; on a 3.5 m lane such a box reaches over the lane line into the parking strip and the
  opposite lane (the cause of moving excavators grazing parked cars). Travelling straight, the box
  is as wide as the tracks or the house (2.6-2.9 m), inside the band
  :func:`generator.traffic.lane_clearance.blocked_lanes` keeps free of static objects. These variants are a
  separate family (tag ``"travel"``, stream ``("assets", "construction_vehicle", "travel", i)``), so
  the static town's excavators do not change.
"""

from __future__ import annotations

import numpy as np

from generator.geometry.mesh import merge

#: kind -> (tag, parameters) of the variant family that drives (kinds not listed: the plain variants)
TRAVEL_POSE = {"construction_vehicle": ("travel", {"slew_deg": 0.0})}

EGO_SIZE_M = (4.6, 1.9)
# spec field -> (asset kind, variants, speed factor of the limit, max acceleration m/s^2, nominal length m)
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


def fleet_proto(lib, kind: str, i: int):
    """Prototype ``i`` of a moving vehicle kind (see the module docstring).

    Parameters
    ----------
    lib : generator.layout.placement_core.Library
    kind : str
        Asset kind (``"car"``, ``"bicyclist"``, ``"construction_vehicle"`` ...).
    i : int
        Variant number.

    Returns
    -------
    generator.layout.placement_core.Proto
        Mesh in the local frame (x forward, y left, z up, origin on the ground), with its bounds.
    """
    if kind in TRAVEL_POSE:
        tag, params = TRAVEL_POSE[kind]
        return lib.variant(kind, i, lambda g: dict(params), tag=tag)
    if kind not in ("bicyclist", "motorcyclist"):
        return lib.variant(kind, i)
    from generator.layout.placement_core import Proto

    key = f"{kind}_riding_v{i}"
    if key not in lib.protos:
        rider = lib.variant(kind, i, lambda g: {"with_vehicle": False})
        vehicle = lib.variant("ridden_bicycle" if kind == "bicyclist" else "ridden_motorcycle", i, stream_kind=kind)
        mesh = merge([vehicle.mesh, rider.mesh])
        lo, hi = mesh.bounds()
        lib.protos[key] = Proto(key, kind, mesh, lo, hi, np.zeros((0, 6)))
    return lib.protos[key]
