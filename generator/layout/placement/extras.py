"""The rarer things of a street: street objects, bike racks, two-wheelers, riders, buses, other
vehicles, walls, driveways and gravel.

Each family has its own density in ``spec.density`` (0 = none, the default, so towns made before
these families existed are unchanged) and its own named stream ``("layout", <family>)``; they are
placed after everything else, so they only fill space the older families left free. Sides and
yaws follow :mod:`generator.layout.placement.street`: side ``s`` of a segment is at ``v * s > 0``.

* street objects (benches, bins, bollards, hydrants, advertising columns) on the kerb line;
* bike racks on the kerb line, with bicycles parked side by side next to them;
* parked bicycles and motorcycles angled in the parking strip;
* riders (the rare-class knob, per km of street): a cyclist or motorcyclist on the kerb side
  of a lane no route drives, or in a free stretch of the parking strip, heading with the
  traffic; rider and two-wheeler are two objects (two instances, as both datasets count them);
* bus stops: a shelter at the back of the sidewalk and, where a lane is free of routes, a bus;
* other vehicles (trailers, box vans, excavators) in the parking strip or a route-free lane;
* walls along lot fronts that have neither hedge nor fence; driveway aprons across the sidewalk
  in front of buildings; gravel patches in parks and yards.
"""

from __future__ import annotations

import numpy as np

from generator.geometry import pose
from generator.layout.lots.lot import Lot
from generator.layout.network.measures import PARKING_START_U
from generator.layout.placement.appearance import fleet_paint, outfit
from generator.layout.placement.placer import Placer
from generator.layout.placement.prototypes import Proto
from generator.layout.placement.street_frame import N_VAR, Street, at, free_lane, sides, variants
from generator.rng import stream
from generator.spec.model import SceneSpec

STREET_OBJECTS = (("bench", 0.25), ("bin", 0.3), ("bollard", 0.25), ("hydrant", 0.1), ("advertising_column", 0.1))
HYDRANT_COLORS = ((0.75, 0.08, 0.06), (0.85, 0.7, 0.05))
KERB_GAP_M = 0.05   #: street furniture keeps this far back from the kerb edge


def place_street_objects(placer: Placer, spec: SceneSpec, st: Street) -> None:
    """Benches, bins, bollards, hydrants and advertising columns on the kerb line, facing the road."""
    dens = spec.density.street_objects_per_100m
    if dens <= 0:
        return
    g = stream(spec.seed, "layout", "street_objects")
    kinds = [k for k, _ in STREET_OBJECTS]
    p = np.array([w for _, w in STREET_OBJECTS])
    protos = {k: variants(placer, k) for k in kinds}
    for seg, s in sides(st):
        to_road, _ = st.side_yaws(seg, s)
        length = seg.length - 2 * st.walk_u0
        for _ in range(int(g.poisson(dens * length / 100))):
            kind = kinds[int(g.choice(len(kinds), p=p / p.sum()))]
            u = g.uniform(st.walk_u0 + 0.5, seg.length - st.walk_u0 - 0.5)
            attrs = {"color": list(HYDRANT_COLORS[int(g.integers(2))])} if kind == "hydrant" else {}
            proto = protos[kind][int(g.integers(N_VAR))]
            # on the kerb line, or further in when the object is wider than the pavement there
            reach = max(float(proto.hi[0]), -float(proto.lo[0]))
            v = s * (st.walk[1] - 0.5 if kind == "bench" else max(st.kerb_line, st.grid.road_half + KERB_GAP_M + reach))
            placer.try_place(proto, *seg.to_world(u, v)[0], st.h, to_road, attrs, pad=0.1)


def place_bike_racks(placer: Placer, spec: SceneSpec, st: Street) -> None:
    """Racks on the kerb line, their row of stands along the kerb, with 1-5 bicycles parked past
    the rack's end, front wheel to the road."""
    dens = spec.density.bike_racks_per_block
    if dens <= 0:
        return
    g = stream(spec.seed, "layout", "bike_racks")
    racks, bikes = variants(placer, "bike_rack"), variants(placer, "bicycle", n=6)
    per_side = dens / 4.0  # a block has four sides
    for seg, s in sides(st):
        to_road, _ = st.side_yaws(seg, s)
        along = seg.yaw
        for _ in range(int(g.poisson(per_side))):
            u = g.uniform(st.walk_u0 + 3.0, seg.length - st.walk_u0 - 8.0)
            v = s * (st.kerb_line + 0.4)
            rack = racks[int(g.integers(N_VAR))]
            # the stands run along the rack's y: turned so the row follows the kerb (across the
            # pavement a long rack would reach over the kerb into the road)
            if not placer.try_place(rack, *seg.to_world(u, v)[0], st.h, along + np.pi / 2, pad=0.05):
                continue
            for k in range(int(g.integers(1, 6))):
                bike = bikes[int(g.integers(len(bikes)))]
                uu = u + float(rack.hi[1]) + 0.5 + 0.75 * k
                placer.try_place(bike, *at(seg, uu, v, bike, to_road), st.h, to_road,
                                 {**fleet_paint(g), "placement": "rack"})


def place_two_wheelers(placer: Placer, spec: SceneSpec, st: Street) -> None:
    """Bicycles and motorcycles parked at an angle in the parking strip."""
    dens = spec.density.parked_two_wheelers_per_100m
    grid = st.grid
    if dens <= 0 or grid.parking_w <= 0:
        return
    g = stream(spec.seed, "layout", "two_wheelers")
    bikes, motos = variants(placer, "bicycle", n=6), variants(placer, "motorcycle")
    for seg, s in sides(st):
        if grid.section(seg).strip(s) != "parking":    # a verge or shoulder (streets spec): no parking
            continue
        _, traffic = st.side_yaws(seg, s)
        u0, u1 = PARKING_START_U, seg.length - PARKING_START_U
        for _ in range(int(g.poisson(dens * max(0.0, u1 - u0) / 100))):
            proto = motos[int(g.integers(N_VAR))] if g.random() < 0.4 else bikes[int(g.integers(len(bikes)))]
            yaw = traffic + s * np.radians(g.uniform(40, 70))
            u, v = g.uniform(u0, u1), s * (grid.lane_half + grid.parking_w * 0.55)
            placer.try_place(proto, *at(seg, u, v, proto, yaw), 0.0, yaw,
                             {**fleet_paint(g), "placement": "parked"}, pad=0.1)


def _ridden(placer: Placer, kind: str, i: int) -> tuple[Proto, Proto]:
    """(rider, vehicle) prototypes of variant ``i``, built from one stream so they fit."""
    vehicle = "ridden_bicycle" if kind == "bicyclist" else "ridden_motorcycle"
    rider = placer.lib.variant(kind, i, lambda g: {"with_vehicle": False})
    return rider, placer.lib.variant(vehicle, i, stream_kind=kind)


def place_riders(placer: Placer, spec: SceneSpec, st: Street) -> None:
    """Cyclists and motorcyclists (``riders_per_km`` of street) with the traffic, off every route."""
    dens = spec.density.riders_per_km
    grid = st.grid
    if dens <= 0:
        return
    g = stream(spec.seed, "layout", "riders")
    total = sum(seg.length for seg in grid.segments) * 2
    spots = []
    for seg, s in sides(st):
        _, traffic = st.side_yaws(seg, s)
        u0, u1 = PARKING_START_U, seg.length - PARKING_START_U
        v_lane = s * (grid.lane_half - 0.9)  # the kerb side of the outer lane, where a cyclist rides
        if u1 > u0 and free_lane(placer, seg, s * (grid.lane_half - grid.lane_w / 2), u0, u1):
            spots.append((seg, traffic, v_lane, u0, u1))
        if grid.parking_w > 0 and grid.section(seg).strip(s) not in ("verge", "furnished"):  # grass, bollards
            spots.append((seg, traffic, s * (grid.lane_half + grid.parking_w / 2), u0, u1))
    if not spots:
        return
    for _ in range(int(g.poisson(dens * total / 1000))):
        seg, traffic, v, u0, u1 = spots[int(g.integers(len(spots)))]
        kind = "bicyclist" if g.random() < 0.65 else "motorcyclist"
        rider, vehicle = _ridden(placer, kind, int(g.integers(N_VAR)))
        u = g.uniform(u0, u1)
        x, y = at(seg, u, v, vehicle, traffic)
        if placer.try_place(vehicle, x, y, 0.0, traffic, {**fleet_paint(g), "placement": "ridden"}, pad=0.3):
            placer.place_on(rider, x, y, 0.0, traffic, outfit(g))


def place_bus_stops(placer: Placer, spec: SceneSpec, st: Street) -> None:
    """Bus stops: a shelter at the back of the sidewalk and a bus standing at it, in a lane no route
    drives; up to :data:`STOP_TRIES` spots along a side are tried for a pair that fits."""
    dens = spec.density.bus_stops_per_km
    grid = st.grid
    if dens <= 0:
        return
    g = stream(spec.seed, "layout", "bus_stops")
    shelters, buses = variants(placer, "bus_shelter", n=2), variants(placer, "bus", n=2)
    for seg, s in sides(st):
        to_road, traffic = st.side_yaws(seg, s)
        if seg.length < 40 or g.random() >= dens * seg.length / 1000:
            continue
        for _ in range(STOP_TRIES):  # the first spot along the side where the bus and its shelter both fit
            u = g.uniform(st.walk_u0 + 8.0, seg.length - st.walk_u0 - 14.0)
            shelter, bus, paint = shelters[int(g.integers(2))], buses[int(g.integers(2))], fleet_paint(g)
            xy = _bus_spot(placer, grid, seg, s, u, bus, traffic)
            v = s * (st.walk[1] - (shelter.hi[0] - shelter.lo[0]) / 2 - 0.2)
            if xy is not None and placer.try_place(shelter, *at(seg, u, v, shelter, to_road), st.h, to_road):
                placer.try_place(bus, *xy, 0.0, traffic, {**paint, "placement": "bus_stop"}, pad=BUS_PAD_M)
                break


STOP_TRIES = 8    #: spots tried along one side of a segment for a bus stop
BUS_PAD_M = 0.3


def _bus_spot(placer: Placer, grid, seg, s: int, u: float, bus: Proto, yaw: float) -> tuple[float, float] | None:
    """World xy of a bus standing at ``u`` in the kerb-side lane (else the next one out) that no route
    drives and where it touches nothing placed; None if there is none."""
    for k in range(grid.lanes):
        v_lane = s * (grid.lane_half - (k + 0.5) * grid.lane_w)
        if free_lane(placer, seg, v_lane, u - 7.0, u + 7.0):
            x, y = at(seg, u, v_lane, bus, yaw)
            T = pose(x, y, 0.0, yaw)
            if placer.fits(bus, T, BUS_PAD_M):
                return x, y
    return None


def place_trams(placer: Placer, spec: SceneSpec, st: Street) -> None:
    """``trams`` trams, each standing on grooved rails laid along a lane no route drives."""
    n = spec.density.trams
    grid = st.grid
    if n <= 0:
        return
    g = stream(spec.seed, "layout", "trams")
    lanes = []
    for seg, s in sides(st):
        u0, u1 = st.walk_u0, seg.length - st.walk_u0
        for k in range(grid.lanes):
            v = s * (grid.lane_half - (k + 0.5) * grid.lane_w)
            if seg.length >= 45 and free_lane(placer, seg, v, u0, u1):
                lanes.append((seg, s, v, u0, u1))
    for _ in range(min(n, len(lanes))):
        seg, s, v, u0, u1 = lanes.pop(int(g.integers(len(lanes))))
        _, traffic = st.side_yaws(seg, s)
        tram = placer.lib.variant("tram", int(g.integers(2)), lambda g2: {"sections": 3})
        if not placer.try_place(tram, *at(seg, (u0 + u1) / 2, v, tram, traffic), 0.0, traffic,
                                {**fleet_paint(g), "placement": "tram_stop"}, pad=0.3):
            continue
        rails = placer.lib.unique("tram_rails", length=float(u1 - u0))
        x, y = seg.to_world((u0 + u1) / 2, v)[0]
        placer.place_on(rails, x, y, 0.0, traffic)


def place_other_vehicles(placer: Placer, spec: SceneSpec, st: Street) -> None:
    """Trailers, box vans and excavators in the parking strip (or a lane no route drives)."""
    dens = spec.density.other_vehicles_per_100m
    grid = st.grid
    if dens <= 0:
        return
    g = stream(spec.seed, "layout", "other_vehicles")
    kinds = {"trailer": variants(placer, "trailer"), "box_van": variants(placer, "box_van"),
             "construction_vehicle": variants(placer, "construction_vehicle", n=2)}
    names, p = list(kinds), np.array([0.45, 0.4, 0.15])
    for seg, s in sides(st):
        if grid.section(seg).strip(s) in ("verge", "furnished"):   # grass or a shared street's bollards:
            continue                                                 # nothing parks there
        _, traffic = st.side_yaws(seg, s)
        u0, u1 = PARKING_START_U, seg.length - PARKING_START_U
        for _ in range(int(g.poisson(dens * max(0.0, u1 - u0) / 100))):
            kind = names[int(g.choice(3, p=p))]
            proto = kinds[kind][int(g.integers(len(kinds[kind])))]
            fits = proto.hi[1] - proto.lo[1] <= grid.parking_w - 0.1
            v = s * (grid.lane_half + grid.parking_w / 2) if fits else s * (grid.lane_half - grid.lane_w / 2)
            placer.try_place(proto, *at(seg, g.uniform(u0, u1), v, proto, traffic), 0.0, traffic,
                             {**fleet_paint(g), "placement": "parked" if fits else "lane"}, pad=0.2)


def _in_rects(x: float, y: float, rects: np.ndarray, pad: float = 1.0) -> bool:
    return bool(((x > rects[:, 0] - pad) & (x < rects[:, 2] + pad) & (y > rects[:, 1] - pad)
                 & (y < rects[:, 3] + pad)).any())


def place_lot_extras(placer: Placer, spec: SceneSpec, lots: list[Lot], st: Street) -> None:
    """Walls along bare lot fronts, driveway aprons across the sidewalk, gravel in parks and yards."""
    dens = spec.density
    g = stream(spec.seed, "layout", "lot_extras")
    lanes = st.grid.drivable_rects()
    for lot in lots:
        if dens.walls > 0 and g.random() < dens.walls:
            length = lot.width - 1.0
            proto = placer.lib.unique("wall", length=float(length), style=str(g.choice(["garden", "retaining"])))
            x, y = lot.to_world([(0.0, 0.35)])[0]
            if not placer.try_place(proto, x, y, st.h, lot.yaw, {"lot": lot.index}):
                placer.lib.discard(proto)
        grid = st.grid
        if lot.use == "building" and dens.driveways > 0 and grid.parking_w > 0 and g.random() < dens.driveways:
            # a dropped kerb in the gutter in front of the lot: ramps from the road up to the kerb
            apron = placer.lib.variant("driveway_apron", int(g.integers(N_VAR)))
            depth = float(apron.hi[0] - apron.lo[0])
            if depth < grid.parking_w:
                a = float(np.clip(lot.entrance_a + g.uniform(2.5, 4.0), -lot.width / 2 + 3, lot.width / 2 - 3))
                b = -(grid.corridor_half - grid.road_half) - depth / 2
                x, y = lot.to_world([(a, b)])[0]
                # not where turning cars run at the segment ends, nor on a raised verge
                if not _in_rects(x, y, lanes) and not (grid.sections and grid.ground_height([(x, y)])[0] > 0):
                    placer.try_place(apron, x, y, 0.0, lot.yaw - np.pi / 2, {"lot": lot.index})
        if lot.use in ("park", "yard") and dens.gravel > 0 and g.random() < dens.gravel:
            patch = placer.lib.variant("gravel_patch", int(g.integers(N_VAR)))
            a, b = g.uniform(-lot.width / 4, lot.width / 4), g.uniform(lot.depth / 4, 3 * lot.depth / 4)
            placer.try_place(patch, *lot.to_world([(a, b)])[0], st.h, float(g.uniform(0, 2 * np.pi)))
