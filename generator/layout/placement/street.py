"""Street furniture, vehicles and people along the streets.

Sidewalk side ``s`` of a segment is the one at ``v * s > 0``; the traffic next to it drives
towards ``-s`` along u (right-hand traffic), so side ``-1`` serves traffic towards +u.
Furniture stands on the kerb-side line of the sidewalk, people walk in its middle, parked
vehicles sit in the parking bays, lane cars on lane centres away from every route.
"""

from __future__ import annotations

import logging

import numpy as np

from generator.layout.network.measures import BAY_M, CROSSWALK_U, PARKING_START_U
from generator.layout.network.one_way import arriving_arms
from generator.layout.placement.appearance import fleet_paint, outfit
from generator.layout.placement.on_lots import N_TREE_VARIANTS, tree_variant
from generator.layout.placement.parks import plant_parks
from generator.layout.placement.placer import Placer
from generator.layout.placement.prototypes import Proto
from generator.layout.placement.roundabouts import place_approach_signs, plant_island
from generator.layout.placement.shared_streets import place_shared_bollards, place_shared_people
from generator.layout.placement.street_frame import Street, free_lane
from generator.layout.placement.variety import DEFAULT_COUNTS, car_variant, person_variants, truck_variant
from generator.rng import stream
from generator.spec.model import SceneSpec

log = logging.getLogger(__name__)

MIN_TREE_M = 3.0        #: the smallest tree the asset builder makes
#: street-tree species (``assets_procedural.tree_species``), one per street-tree variant
STREET_SPECIES = ("linden", "plane", "birch", "young")
SIGN_SHAPES = ("circle", "triangle", "square", "octagon", "diamond")
N_LAMP, N_TL, N_STREET_TREE = 3, 2, 4    #: cars, trucks, people: the spec's assets.variants (variety.py)


def place_traffic_lights(placer: Placer, spec: SceneSpec, st: Street) -> None:
    """One signal per approach on its near-right corner, facing the approaching traffic (at a
    roundabout a round sign instead, and bushes on its island). The arm of a one-way street that
    runs away from the node is no approach and gets no head (:func:`arriving_arms`)."""
    grid = st.grid
    protos = [placer.lib.variant("traffic_light", i, lambda g: {"arm": 0.0}) for i in range(N_TL)]
    q = st.kerb_line
    for n_i, node in enumerate(grid.nodes):
        if grid.is_roundabout(node):        # no signal heads: round signs, bushes on the island
            place_approach_signs(placer, grid, node, q, st.h)
            plant_island(placer, grid, node, spec.seed, st.h)
            continue
        c = grid.node_xy(node)
        for d in arriving_arms(grid, node):
            yaw = d * np.pi / 2
            e = np.array([np.cos(yaw), np.sin(yaw)])
            left = np.array([-e[1], e[0]])
            x, y = c + e * q + left * q
            placer.try_place(protos[(n_i + d) % N_TL], x, y, st.h, yaw)


def place_lamps(placer: Placer, spec: SceneSpec, st: Street) -> None:
    """Lamp posts on the kerb line, arms over the parking strip (never over a route lane)."""
    grid = st.grid
    reach = max(0.3, min(2.5, st.kerb_line - grid.lane_half - 0.6))
    protos = [placer.lib.variant("lamp_post", i, lambda g, i=i: {"height": float(g.uniform(6.0, 8.5)),
                                                                  "arm": reach * (0.6, 0.8, 1.0)[i]})
              for i in range(N_LAMP)]
    g = stream(spec.seed, "layout", "lamps")
    spacing = spec.density.lamp_spacing_m
    for seg in grid.segments:
        for s in (-1, 1):
            to_road, _ = st.side_yaws(seg, s)
            start = (0.25 if s < 0 else 0.75) * spacing * g.uniform(0.8, 1.2)
            for u in st.along(seg, start, spacing, g):
                x, y = seg.to_world(u, s * st.kerb_line)[0]
                placer.try_place(protos[int(g.integers(N_LAMP))], x, y, st.h, to_road, pad=0.2)


def street_tree_variants(placer: Placer, spec: SceneSpec, half_width: float, tag: str = "street") -> list[Proto]:
    """Street-tree variants whose crown stays within ``half_width`` metres of the trunk (so it
    never reaches over a route lane); a variant that comes out too wide is rebuilt shorter.
    ``tag`` names the variant family (another width limit needs its own family)."""
    lo, hi = spec.heights.tree_m
    out = []
    for i in range(N_STREET_TREE):
        species = STREET_SPECIES[i % len(STREET_SPECIES)]
        for attempt in range(6):
            def params(g, attempt=attempt, species=species):
                return {"height": float(max(MIN_TREE_M, g.uniform(lo, hi) * 0.85 ** attempt)), "species": species}
            proto = placer.lib.variant("tree", i, params, tag=f"{tag}{attempt}")
            if max(-proto.lo[0], proto.hi[0], -proto.lo[1], proto.hi[1]) <= half_width:
                out.append(proto)
                break
            placer.lib.discard(proto)
            if proto.params["height"] <= MIN_TREE_M:
                break
    return out


def place_street_trees(placer: Placer, spec: SceneSpec, st: Street) -> None:
    """Trees on the kerb line, ``trees_per_100m`` per sidewalk with jittered spacing, crowns
    narrow enough to keep clear of the route lanes; and the pocket parks of closed streets."""
    plant_parks(placer, spec, st.grid, st.h)
    if spec.density.trees_per_100m <= 0:
        return
    grid = st.grid
    route_v = (grid.lanes - 0.5) * grid.lane_w          # |v| of a route's lane centre
    half = st.kerb_line - route_v - placer.keepout.limit - 0.1
    protos = street_tree_variants(placer, spec, half)
    if not protos:      # no crown is narrow enough for a route street: trees only where no route drives
        log.info("no street-tree crown fits within %.2f m of the kerb line; using park trees", half)
        protos = [tree_variant(placer, spec, i) for i in range(N_TREE_VARIANTS)]
    g = stream(spec.seed, "layout", "trees")
    spacing = 100.0 / spec.density.trees_per_100m
    for seg in grid.segments:
        for s in (-1, 1):
            for u in st.along(seg, g.uniform(0, spacing), spacing, g):
                x, y = seg.to_world(u + g.uniform(-0.5, 0.5), s * st.kerb_line)[0]
                yaw = seg.yaw + int(g.integers(4)) * np.pi / 2      # axis-aligned: tight box across the street
                placer.try_place(protos[int(g.integers(len(protos)))], x, y, st.h, yaw, pad=0.3)


def place_signs(placer: Placer, spec: SceneSpec, st: Street) -> None:
    """``signs_per_block`` signs per block: half before intersections, half along sidewalks, facing traffic."""
    grid = st.grid
    g = stream(spec.seed, "layout", "signs")
    protos = [placer.lib.variant("traffic_sign", i, lambda g, i=i: {"shape": SIGN_SHAPES[i]})
              for i in range(len(SIGN_SHAPES))]
    n_blocks = (len(grid.xs) - 1) * (len(grid.ys) - 1)
    total = int(round(spec.density.signs_per_block * n_blocks))
    for k in range(total):
        proto = protos[int(g.integers(len(protos)))]
        for _ in range(8):
            seg = grid.segments[int(g.integers(len(grid.segments)))]
            s = int(g.choice([-1, 1]))
            _, traffic = st.side_yaws(seg, s)
            if k % 2 == 0:   # just before the intersection the traffic on this side drives to
                back = st.walk_u0 + 1.0 + g.uniform(0, 3.0)
                u = seg.length - back if s < 0 else back
            else:
                u = g.uniform(st.walk_u0 + 2, seg.length - st.walk_u0 - 2)
            x, y = seg.to_world(u, s * st.kerb_line)[0]
            if placer.try_place(proto, x, y, st.h, traffic + np.pi, pad=0.2):
                break


def _vehicle(placer: Placer, kind: str, i: int) -> Proto:
    return car_variant(placer.lib, i) if kind == "car" else truck_variant(placer.lib, i)


def place_parked(placer: Placer, spec: SceneSpec, st: Street) -> None:
    """Cars (one bay) and trucks (two bays) in the parking strips, facing the traffic of their side.

    A truck wider than the strip double-parks in the lane next to it instead (only where no
    route drives that lane; the keep-out rejects it otherwise). Without ``spec.streets`` every
    bay is taken with probability ``parked_cars_per_100m * BAY_M / 100``; with it, each strip
    has its own share (:attr:`CrossSection.occupancy`) and strips that are verges or shoulders
    get none.
    """
    grid = st.grid
    place_shared_bollards(placer, spec, st)    # hook: shared streets' strips hold bollards, not cars
    if grid.parking_w <= 0 or spec.density.parked_cars_per_100m <= 0:
        return
    g = stream(spec.seed, "layout", "parked")
    paint = stream(spec.seed, "layout", "parked", "paint")      # colours never move a car
    n_car, n_truck = placer.lib.count("car", DEFAULT_COUNTS["car"]), placer.lib.count("truck", DEFAULT_COUNTS["truck"])
    trucks = [_vehicle(placer, "truck", i) for i in range(n_truck)]
    p_occ = min(1.0, spec.density.parked_cars_per_100m * BAY_M / 100.0)
    for seg in grid.segments:
        u0, u1 = PARKING_START_U, seg.length - PARKING_START_U
        n_bays = int((u1 - u0 + 1e-6) // BAY_M)
        sec = grid.section(seg)
        for s in (-1, 1):
            if grid.sections and sec.strip(s) != "parking":
                continue
            share = sec.share(s) if grid.sections else p_occ
            _, traffic = st.side_yaws(seg, s)
            b = 0
            while b < n_bays:
                if g.random() >= share:
                    b += 1
                    continue
                truck = b + 1 < n_bays and g.random() < spec.density.truck_fraction
                proto = trucks[int(g.integers(n_truck))] if truck else _vehicle(placer, "car", int(g.integers(n_car)))
                nb = 2 if truck else 1
                fits = proto.hi[1] - proto.lo[1] <= grid.parking_w - 0.1
                if not fits and spec.traffic.enabled:  # moving traffic needs the lane: no double parking
                    b += nb
                    continue
                v = s * (grid.lane_half + grid.parking_w / 2) if fits else s * (grid.lane_half - grid.lane_w / 2)
                u = u0 + (b + nb / 2) * BAY_M
                c = (proto.lo + proto.hi) / 2     # centre the body (not the local origin) on the spot
                ct, sn = np.cos(traffic), np.sin(traffic)
                x, y = seg.to_world(u, v)[0] - [c[0] * ct - c[1] * sn, c[0] * sn + c[1] * ct]
                placer.try_place(proto, x, y, 0.0, traffic, {**fleet_paint(paint),
                                 "placement": "parked" if fits else "double_parked"}, pad=0.2)
                b += nb


def place_lane_cars(placer: Placer, spec: SceneSpec, st: Street) -> None:
    """``moving_cars_per_100m`` cars (and the truck share of trucks) standing mid-block on lane
    centres, spread over the lanes no route drives."""
    grid = st.grid
    dens = spec.density.moving_cars_per_100m
    if dens <= 0 or spec.traffic.enabled:  # the frozen town's stand-ins for traffic; real traffic replaces them
        return
    g = stream(spec.seed, "layout", "lane_cars")
    paint = stream(spec.seed, "layout", "lane_cars", "paint")
    lanes = []
    for seg in grid.segments:
        u0, u1 = PARKING_START_U + 4.0, seg.length - PARKING_START_U - 4.0
        for d in (1, -1):
            for k in range(grid.lanes):
                v = -d * (k + 0.5) * grid.lane_w
                if u1 > u0 and free_lane(placer, seg, v, u0, u1):
                    lanes.append((seg, d, v, u0, u1))
    if not lanes:
        return
    lengths = np.array([u1 - u0 for *_, u0, u1 in lanes])
    n = int(round(dens * lengths.sum() / 100))
    for _ in range(n):
        seg, d, v, u0, u1 = lanes[int(g.choice(len(lanes), p=lengths / lengths.sum()))]
        heading = seg.yaw if (grid.section(seg).one_way or d) > 0 else seg.yaw + np.pi   # one-way: its way
        kind = "truck" if g.random() < spec.density.truck_fraction else "car"
        proto = _vehicle(placer, kind, int(g.integers(placer.lib.count("car", DEFAULT_COUNTS["car"]))))
        x, y = seg.to_world(g.uniform(u0, u1), v)[0]
        placer.try_place(proto, x, y, 0.0, heading, {**fleet_paint(paint), "placement": "lane"}, pad=0.5)


def place_people(placer: Placer, spec: SceneSpec, st: Street) -> None:
    """People standing or walking on the sidewalks; about one in eight on a crosswalk."""
    grid = st.grid
    if spec.density.people_per_100m <= 0:
        return
    g = stream(spec.seed, "layout", "people")
    look = stream(spec.seed, "layout", "people", "outfit")     # outfits never move a person
    protos = person_variants(placer.lib, spec)
    n_people = len(protos)
    for seg in grid.segments:
        length = seg.length - 2 * st.walk_u0
        for s in (-1, 1):
            for _ in range(int(g.poisson(spec.density.people_per_100m * length / 100))):
                i = int(g.integers(n_people))
                u = g.uniform(st.walk_u0 + 0.5, seg.length - st.walk_u0 - 0.5)
                x, y = seg.to_world(u, s * g.uniform(*st.walk))[0]
                yaw = seg.yaw + (0 if g.random() < 0.5 else np.pi) + g.normal(0, 0.1) if i >= n_people // 2 \
                    else g.uniform(0, 2 * np.pi)
                placer.try_place(protos[i], x, y, st.h, yaw, outfit(look), pad=0.15)
        if g.random() < 0.25 and not spec.traffic.enabled:  # someone frozen on a crosswalk (traffic: they walk)
            u = g.uniform(*CROSSWALK_U) if g.random() < 0.5 else seg.length - g.uniform(*CROSSWALK_U)
            v = g.uniform(-grid.road_half + 0.6, grid.road_half - 0.6)
            x, y = seg.to_world(u, v)[0]
            yaw = seg.yaw + (np.pi / 2 if g.random() < 0.5 else -np.pi / 2)
            i = n_people // 2 + int(g.integers(n_people - n_people // 2))
            placer.try_place(protos[i], x, y, 0.0, yaw, {**outfit(look), "placement": "crosswalk"}, pad=0.15)
    place_shared_people(placer, spec, st, protos, look)   # hook: people on shared carriageways
