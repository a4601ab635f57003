"""``build_scene(spec) -> SceneModel``: the whole procedural town, deterministic in the spec.

Order of work (each feature draws from its own named stream, so adding one does not
shift the others): grid -> routes -> lots (blocks, then the band outside the ring road)
-> buildings -> hedges/fences -> traffic lights -> one-way signs
-> lamps -> street trees -> verge hedges, bushes and trees -> signs -> lot greenery -> parked vehicles -> lane cars ->
people -> ground objects. Objects accepted earlier win space; everything keeps clear of
the routes (see :mod:`generator.layout.placement`). Finally the routes are verified
against every object box, and an internal error is raised if any sample is too close.
"""

from __future__ import annotations

import logging
import time
from collections import defaultdict

import numpy as np

from generator.geometry import Mesh, pose
from generator.geometry.boxes import box_of
from generator.labels import class_table
from generator.layout.ground.far_city import far_city
from generator.layout.ground.intersections import intersection_road_mesh, intersection_walk_mesh
from generator.layout.ground.roads import segment_road_mesh
from generator.layout.ground.sidewalks import segment_walk_mesh
from generator.layout.ground.terrain import horizon_mesh, margin_mesh
from generator.layout.lots.lot import Lot, lot_ground_mesh, make_lots
from generator.layout.mapping.mapped_scene import map_scene, verify_world_routes
from generator.layout.mapping.town_map import draw_town_map
from generator.layout.network.design_vehicle import EGO_HALF_WIDTH_M
from generator.layout.network.draw import make_grid
from generator.layout.network.grid import Grid, segment_frame_points
from generator.layout.network.routes import densify, make_routes
from generator.layout.placement import extras as px
from generator.layout.placement import on_lots as pl
from generator.layout.placement import one_way_signs as pw
from generator.layout.placement import street as ps
from generator.layout.placement import tracks as pt
from generator.layout.placement import verges as pv
from generator.layout.placement.keepout import Keepout
from generator.layout.placement.placer import Placed, Placer
from generator.layout.placement.prototypes import Library
from generator.layout.placement.variety import variant_counts
from generator.layout.town import Town
from generator.progress import progress
from generator.spec.model import SceneSpec
from generator.spec.towns import library_seed
from generator.world.scene import Path, SceneModel, SceneObject

log = logging.getLogger(__name__)

MAX_INSTANCES = 65535

#: Placement steps in the order they claim space.
STEPS = (
    ("buildings", lambda p, s, g, lots, st: pl.place_buildings(p, s, lots, g.curb_h)),
    ("hedges and fences", lambda p, s, g, lots, st: pl.place_fronts(p, s, lots, g.curb_h)),
    ("traffic lights", lambda p, s, g, lots, st: ps.place_traffic_lights(p, s, st)),
    # one-way streets' "one way" and "no entry" signs (a no-op without one-way streets)
    ("one-way signs", lambda p, s, g, lots, st: pw.place_one_way_signs(p, s, st)),
    ("lamp posts", lambda p, s, g, lots, st: ps.place_lamps(p, s, st)),
    ("street trees", lambda p, s, g, lots, st: ps.place_street_trees(p, s, st)),
    # verges exist only in towns with a streets spec (no-ops otherwise)
    # (paved crossings first, then residential verge hedges: the verge trees then stand in their gaps)
    ("verge crossings", lambda p, s, g, lots, st: pv.place_verge_crossings(p, s, lots, st)),
    ("verge hedges and bushes", lambda p, s, g, lots, st: pv.place_verge_bushes(p, s, st)),
    ("verge trees", lambda p, s, g, lots, st: pv.place_verge_trees(p, s, st)),
    ("traffic signs", lambda p, s, g, lots, st: ps.place_signs(p, s, st)),
    ("lot greenery", lambda p, s, g, lots, st: pl.place_lot_greenery(p, s, lots, g.curb_h)),
    ("parked vehicles", lambda p, s, g, lots, st: ps.place_parked(p, s, st)),
    # trams need a whole free lane: before the lane cars (a no-op at the default trams = 0)
    ("trams", lambda p, s, g, lots, st: px.place_trams(p, s, st)),
    ("lane cars", lambda p, s, g, lots, st: ps.place_lane_cars(p, s, st)),
    ("people", lambda p, s, g, lots, st: ps.place_people(p, s, st)),
    # families added later: placed last, each from its own stream, density 0 by default
    ("street objects", lambda p, s, g, lots, st: px.place_street_objects(p, s, st)),
    ("bike racks", lambda p, s, g, lots, st: px.place_bike_racks(p, s, st)),
    ("two-wheelers", lambda p, s, g, lots, st: px.place_two_wheelers(p, s, st)),
    ("bus stops", lambda p, s, g, lots, st: px.place_bus_stops(p, s, st)),
    ("other vehicles", lambda p, s, g, lots, st: px.place_other_vehicles(p, s, st)),
    ("riders", lambda p, s, g, lots, st: px.place_riders(p, s, st)),
    ("lot extras", lambda p, s, g, lots, st: px.place_lot_extras(p, s, lots, st)),
    # where trams run, their line also leaves the street on a ballast bed (a no-op at trams = 0)
    ("tram track", lambda p, s, g, lots, st: pt.place_tram_track(p, s, lots, st)),
)


class LayoutError(RuntimeError):
    """An internal invariant of the layout is broken (a bug, not a user error)."""


def _pits(grid: Grid, seg, trees: np.ndarray) -> np.ndarray:
    """(k, 2) segment-frame centres of the street trees standing on ``seg``'s sidewalks."""
    if not len(trees):
        return np.zeros((0, 2))
    uv = segment_frame_points(seg, trees)
    u0 = grid.corridor_half - grid.road_half
    on = (np.abs(uv[:, 1]) > grid.walk_inner) & (np.abs(uv[:, 1]) < grid.corridor_half) \
        & (uv[:, 0] > u0) & (uv[:, 0] < seg.length - u0)
    return uv[on]


def ground_pieces(grid: Grid, lots: list[Lot],
                  placed: list[Placed] = ()) -> list[tuple[str, str, str, Mesh, np.ndarray]]:
    """Stuff objects: ``(kind, class, prototype key or "", mesh, transform)``.

    One road and one sidewalk object (with tree pits under the street trees of ``placed``)
    per street segment, one asphalt square (shared prototype) and one corner-sidewalk
    object per intersection, one ground per lot, the terrain margin round the built area,
    and the flat ground beyond it to the horizon (kind ``horizon``).
    """
    out = []
    trees = np.array([p.transform[:2, 3] for p in placed if p.kind == "tree"]).reshape(-1, 2)
    for seg in grid.segments:
        T = seg.transform()
        out.append(("street", "road", "", segment_road_mesh(grid, seg), T))
        out.append(("sidewalk", "sidewalk", "", segment_walk_mesh(grid, seg, _pits(grid, seg, trees)), T))
    square = intersection_road_mesh(grid)
    for node in grid.nodes:
        T = pose(*grid.node_xy(node))
        out.append(("intersection", "road", "intersection_road", square, T))
        out.append(("corner", "sidewalk", "", intersection_walk_mesh(grid, node), T))
    for lot in lots:
        out.append(("lot_ground", "terrain" if lot.ground == "grass" else "sidewalk", "",
                    lot_ground_mesh(lot, grid.curb_h), lot.transform()))
    if grid.margin > 0:
        out.append(("terrain", "terrain", "", margin_mesh(grid), np.eye(4)))
    out.append(("horizon", "terrain", "", horizon_mesh(grid), np.eye(4)))
    return out


def _objects(grid: Grid, lots: list[Lot], placed: list[Placed], lib: Library):
    prototypes: dict[str, Mesh] = {}
    proxies: dict[str, Mesh] = {}
    objects: list[SceneObject] = []
    counters: dict[str, int] = defaultdict(int)

    def name(kind: str) -> str:
        counters[kind] += 1
        return f"{kind}_{counters[kind] - 1:04d}"

    for kind, cls, key, mesh, T in ground_pieces(grid, lots, placed):
        nm = name(kind)
        key = key or nm
        prototypes.setdefault(key, mesh)
        lo, hi = mesh.bounds()
        objects.append(SceneObject(len(objects), nm, kind, cls, 0, key, T, box_of(lo, hi, T)))
    is_thing = [r.thing for r in class_table().rows]
    n_things = sum(is_thing[class_table().id(p.cls)] for p in placed)
    if n_things > MAX_INSTANCES:
        raise LayoutError(f"{n_things} things exceed the {MAX_INSTANCES} instance ids of a uint16 label")
    things = 0
    for p in placed:
        instance = 0
        if is_thing[class_table().id(p.cls)]:  # instance ids for things only, as SemanticKITTI and Cityscapes
            things += 1
            instance = things
        if p.proto not in prototypes:
            mesh = lib.protos[p.proto].mesh
            prototypes[p.proto] = mesh
            hull = lib.label_proxy(p.proto)
            if hull is not None:
                proxies[p.proto] = hull
        objects.append(SceneObject(len(objects), name(p.kind), p.kind, p.cls, instance, p.proto, p.transform, p.box,
                                   p.proto if p.proto in proxies else None, p.attrs))
    return prototypes, proxies, objects


def verify_routes(paths: list[Path], grid: Grid, objects: list[SceneObject], limit: float) -> None:
    """Raise :class:`LayoutError` unless every route sample lies on driving-lane asphalt and keeps
    ``limit`` metres (2D) from the box of every placed object in ``objects``."""
    drive = grid.drivable_rects()
    for path in paths:
        xy = path.points[:, :2]
        inside = ((xy[:, None, 0] >= drive[None, :, 0] - 1e-6) & (xy[:, None, 0] <= drive[None, :, 2] + 1e-6)
                  & (xy[:, None, 1] >= drive[None, :, 1] - 1e-6) & (xy[:, None, 1] <= drive[None, :, 3] + 1e-6)).any(1)
        if not inside.all():
            raise LayoutError(f"{path.name}: {int((~inside).sum())} samples off the driving lanes, "
                              f"e.g. {xy[~inside][0]}")
        keep = Keepout(xy, limit)
        for o in objects:
            d = keep.distance(o.box)
            if d < limit:
                raise LayoutError(f"{path.name}: {o.name} is {d:.2f} m from the route (< {limit:.2f} m)")


def _far_city(spec: SceneSpec, grid: Grid, prototypes: dict[str, Mesh], proxies: dict[str, Mesh],
              objects: list[SceneObject]) -> int:
    """Append the city beyond the town (:mod:`generator.layout.ground.far_city`) after every other object,
    so every town object keeps its index; returns the index of the first far-city object.

    Each object stands where its footprint's centre is (its transform; the mesh local to it), on no
    lot of the town (``attrs["lot"]`` None), as stuff (instance 0). Crowns are closed solids,
    so the label proxy of an object with crowns (vegetation's hull policy) is its crowns themselves,
    without a hull that would fill the gaps between the trees (or cover the buildings beside a park)."""
    start = len(objects)
    counters: dict[str, int] = defaultdict(int)
    hull = class_table().hull_classes
    for kind, cls, world in far_city(spec.seed, grid.bounds, grid.curb_h):
        name = f"{kind}_{counters[kind]:04d}"
        counters[kind] += 1
        lo, hi = world.bounds()
        T = pose(float((lo[0] + hi[0]) / 2), float((lo[1] + hi[1]) / 2))
        mesh = world.transformed(np.linalg.inv(T))
        prototypes[name] = mesh
        proxy = None
        crowns = hull[mesh.face_class]
        if crowns.any():
            proxies[name], proxy = (mesh if crowns.all() else mesh.select(crowns)), name
        lo, hi = mesh.bounds()
        objects.append(SceneObject(len(objects), name, kind, cls, 0, name, T, box_of(lo, hi, T), proxy,
                                   {"lot": None}))
    return start


def build_scene(spec: SceneSpec) -> Town:
    """Build the town described by ``spec``.

    Returns
    -------
    Town
        The scene (a :class:`~generator.world.scene.SceneModel`) with the grid and asset library it
        was built from (and the map of a town whose streets cross at an angle). Ground pieces
        first, then placed objects in placement order; objects of thing classes (``thing`` in
        ``classes.yaml``) get instance ids 1..N, stuff gets 0; route 0 is the comb loop
        :class:`generator.world.rig.Rig` follows.

    Raises
    ------
    LayoutError
        If a route ends up off the lanes or too close to an object (a bug).
    """
    t0 = time.perf_counter()
    grid = make_grid(spec)
    routes = make_routes(grid)
    lots = make_lots(spec, grid)
    limit = spec.paths.clearance_m + EGO_HALF_WIDTH_M
    keepout = Keepout(np.concatenate([densify(r) for r in routes]), limit)
    lib = Library(library_seed(spec), variant_counts(spec))   # a fresh library per town (or every M towns)
    tmap = draw_town_map(spec, grid)
    placer = Placer(lib, keepout, town_map=tmap)   # with a map: laid out on the grid, checked in the world
    street = ps.Street(grid)
    log.info("layout %s: %d x %d blocks, %d segments, %d lots", spec.name, len(grid.xs) - 1, len(grid.ys) - 1,
             len(grid.segments), len(lots))
    for label, step in progress(STEPS, desc=f"layout {spec.name}", unit="step", leave=False):
        n0, t1 = len(placer.placed), time.perf_counter()
        step(placer, spec, grid, lots, street)
        log.info("placed %d %s (%.2f s)", len(placer.placed) - n0, label, time.perf_counter() - t1)
    prototypes, proxies, objects = _objects(grid, lots, placer.placed, lib)
    first = len(objects) - len(placer.placed)
    beyond = _far_city(spec, grid, prototypes, proxies, objects)
    scene = SceneModel(spec.seed, spec.spec_hash, grid.bounds, prototypes, proxies, objects, routes)
    if tmap is None:
        verify_routes(routes, grid, objects[first:beyond], limit - 1e-6)
        town = Town.of(scene, grid, lib)
    else:
        verify_routes(routes, grid, [], limit)      # on the lanes (the grid's); distances in the world:
        shaped = set(range(first)) | {first + i for i, p in enumerate(placer.placed) if lib.protos[p.proto].shaped}
        shaped |= set(range(beyond, len(objects)))          # the far city is laid out on the grid too
        world = map_scene(scene, tmap, shaped)
        verify_world_routes(world, scene, tmap, first, shaped, limit - 1e-6, beyond)
        log.info("streets cross at %.1f degrees (lean %+d): the town is mapped from its grid", tmap.angle_deg,
                 tmap.lean)
        town = Town.of(world, grid, lib, tmap, scene)
    log.info("scene %s: %d objects, %d prototypes, %d proxies, built in %.2f s", spec.name, len(objects),
             len(town.prototypes), len(town.proxies), time.perf_counter() - t0)
    return town


def class_counts(scene: SceneModel) -> dict[str, dict[str, int]]:
    """Objects (by main class) and triangles (by face class) per class name."""
    names = class_table().names
    tri = np.bincount(scene.face_class, minlength=len(names))
    objs: dict[str, int] = defaultdict(int)
    for o in scene.objects:
        objs[o.cls] += 1
    return {n: {"objects": int(objs.get(n, 0)), "triangles": int(tri[i])} for i, n in enumerate(names)}
