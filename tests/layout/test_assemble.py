"""The procedural town: deterministic, complete, nothing where it must not be, routes drivable."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from generator.geometry import apply
from generator.geometry.boxes import boxes_overlap, point_box_distance
from generator.labels import class_table
from generator.layout import build_scene
from generator.layout.ground.terrain import HORIZON_M
from generator.layout.lots.lot import make_lots
from generator.layout.network.design_vehicle import EGO_HALF_WIDTH_M
from generator.layout.network.draw import make_grid
from generator.layout.network.grid import segment_frame_points
from generator.layout.network.measures import MARK_Z_M
from generator.materials import material_table
from generator.previews.layout_map import rasterize
from generator.spec import parse_spec
from generator.world.rig import Rig
from generator.world.scene import OrientedBox
from kits.town_checks import check_vehicles


def _rect_boxes(rects) -> np.ndarray:
    """(k, 4) AABBs -> (k, 7) boxes for :func:`overlaps` (z spans everything)."""
    r = np.asarray(rects, np.float64).reshape(-1, 4)
    c, h = (r[:, :2] + r[:, 2:]) / 2, (r[:, 2:] - r[:, :2]) / 2
    return np.c_[c, h, np.zeros(len(r)), np.full(len(r), -1e9), np.full(len(r), 1e9)]


def _obj_boxes(objs, shrink: float = 0.0) -> np.ndarray:
    return np.array([[*o.box.center[:2], o.box.size[0] / 2 - shrink, o.box.size[1] / 2 - shrink, o.box.yaw,
                      -1e9, 1e9] for o in objs])


def _world_vertices(scene, o) -> np.ndarray:
    return apply(o.transform, scene.prototypes[o.prototype].vertices)


# -- determinism ------------------------------------------------------------------------------
def test_same_spec_gives_identical_scene(test_spec, test_scene):
    again = build_scene(test_spec)
    assert again.digest() == test_scene.digest()
    assert np.array_equal(again.vertices, test_scene.vertices)


def test_different_seed_gives_different_town(test_spec, test_scene):
    other = build_scene(dataclasses.replace(test_spec, seed=test_spec.seed + 1))
    assert other.digest() != test_scene.digest()
    boxes = {o.name: o.box.center for o in test_scene.objects}
    moved = [n for n, c in ((o.name, o.box.center) for o in other.objects) if boxes.get(n) != c]
    assert len(moved) > len(other.objects) // 4, "a new seed should move much of the town, not a detail"


# -- completeness -----------------------------------------------------------------------------
#: Classes only the presets with the newer families place (their densities default to 0, so the
#: default town stays as it was): see test_city_centre_has_every_class.
NEWER_FAMILIES = {"bicycle", "motorcycle", "bus", "on_rails", "other_vehicle", "bicyclist", "motorcyclist", "wall",
                  "other_ground", "street_object", "rail_track", "shelter", "ridden_bicycle", "ridden_motorcycle"}
#: SceneModel.digest() of scenes/default_town.json without its traffic (the frozen town of before
#: traffic existed: lane cars, double-parked trucks, a person on a crosswalk). The newer families
#: must not change it; update it only for a change that means to alter the default town, and say so
#: in the commit. Re-pinned for issue 29 (asset variety: 48 car and 48 person variants drawn by body
#: type and by age and sex change every car and person of the town; nothing moved). Re-pinned for
#: issue 29 item 6: the far city (blocks, parks, tree line, skyline) is appended after every town
#: object; the town's own objects, meshes, indices and routes are byte-identical to before. Re-pinned
#: for the far city joined into 12 objects, with rounder crowns and its tree line 14 m beyond the bounds
#: (the scene built without the far city still has main's digest). Re-pinned for the tree line's trunks
#: and three-lobed crowns (its own stream: the town, blocks and skyline are byte-identical). Re-pinned for
#: issue 29 item 1 (foliage: leaf skins on hedges and bushes, twig-wise leaf sprays and smaller crown cores
#: on trees; with the reshaped prototypes the town with its traffic places 184 trees instead of 183). Re-pinned
#: for issue 29 item 3's car bodies (lamp lenses on the shell, a domed roof, black pillars: every car mesh changed)
#: and item 4 (people shaped, not tubes: every person mesh changed; nothing moved).
DEFAULT_TOWN_DIGEST = "22c0617c52ff2c4768894cf6400f6381fbd9a050de706c295c5d92f3ee1dc8e9"


def test_every_class_is_present_in_the_default_town(default_spec, default_scene):
    table = class_table()
    tri = np.bincount(default_scene.face_class, minlength=len(table))
    missing = [n for i, n in enumerate(table.names) if n not in ("unlabeled", "sky") and tri[i] == 0]
    # with traffic on, trucks too wide for a parking strip drive instead of double-parking
    in_traffic = {"truck"} if default_spec.traffic.trucks_per_km > 0 else set()
    assert set(missing) <= NEWER_FAMILIES | in_traffic, missing
    assert tri[table.id("unlabeled")] == 0 and tri[table.id("sky")] == 0


def test_default_town_is_reproducible(root):
    """The frozen default town has the pinned bytes (built in a process with the arithmetic the
    digest was recorded with: tests/kits/reference_arithmetic.py)."""
    import subprocess
    import sys

    from kits.reference_arithmetic import reference_env, why_not

    env = reference_env()
    if env is None:
        pytest.skip(why_not())
    code = ("import json, pathlib; from generator.spec.load import parse_spec; "
            "from generator.layout import build_scene; "
            "doc = json.loads(pathlib.Path('scenes/default_town.json').read_text()); doc.pop('traffic', None); "
            "print(build_scene(parse_spec(doc, 'default_town.json')).digest())")
    run = subprocess.run([sys.executable, "-c", code], cwd=root, env=env, capture_output=True, text=True, check=True)
    assert run.stdout.split()[-1] == DEFAULT_TOWN_DIGEST


@pytest.fixture(scope="module")
def city_centre(root):
    from generator.spec import load_spec

    return build_scene(load_spec(root / "scenes" / "city_centre.json"))


def test_city_centre_has_every_class(city_centre):
    """Every class a street has (all but unlabeled, sky and the off-street rail track bed)."""
    table = class_table()
    tri = np.bincount(city_centre.face_class, minlength=len(table))
    missing = [n for i, n in enumerate(table.names) if tri[i] == 0 and n not in ("unlabeled", "sky", "rail_track")]
    assert not missing


def test_riders_sit_on_their_two_wheelers(city_centre):
    """A rider and its ridden vehicle are two objects (two instances) under one transform."""
    objs = city_centre.objects
    riders = [o for o in objs if o.cls in ("bicyclist", "motorcyclist")]
    assert riders
    for r in riders:
        below = objs[r.index - 1]
        assert below.cls == {"bicyclist": "ridden_bicycle", "motorcyclist": "ridden_motorcycle"}[r.cls]
        np.testing.assert_allclose(r.transform, below.transform)
        assert r.instance_id > 0 and below.instance_id > 0 and r.instance_id != below.instance_id


def test_only_vehicles_stand_in_the_lanes_and_none_on_a_route(city_centre, root):
    """On the driving lanes stand only vehicles, riders, tram rails and people on crosswalks; every
    placed object keeps the route clearance (the same check build_scene makes)."""
    from generator.layout.assemble import verify_routes
    from generator.layout.network.draw import make_grid
    from generator.spec import load_spec

    grid = make_grid(load_spec(root / "scenes" / "city_centre.json"))
    ground = ("street", "sidewalk", "intersection", "corner", "lot_ground", "terrain", "horizon")
    placed = [o for o in city_centre.objects if o.kind not in ground]
    verify_routes(city_centre.paths, grid, [o for o in placed if o.kind != "tram_rails"], 0.5)
    lanes = grid.drivable_rects()
    on_lanes = ("car", "truck", "bus", "on_rails", "other_vehicle", "ridden_bicycle", "ridden_motorcycle",
                "bicyclist", "motorcyclist", "road")
    for o in placed:
        x, y = o.transform[:2, 3]  # where it stands (a lamp's arm may reach over the lane)
        inside = ((x > lanes[:, 0]) & (x < lanes[:, 2]) & (y > lanes[:, 1]) & (y < lanes[:, 3])).any()
        if inside:
            assert o.cls in on_lanes or o.attrs.get("placement") == "crosswalk", (o.name, o.cls)


def test_ids_are_valid(default_scene):
    s = default_scene
    assert s.face_class.max() < len(class_table())
    assert s.face_material.max() < len(material_table())
    things = [o for o in s.objects if o.instance_id > 0]
    ids = [o.instance_id for o in things]
    assert sorted(ids) == list(range(1, len(ids) + 1))
    table = class_table()
    for o in s.objects:
        assert table[o.cls].thing == (o.instance_id > 0), o.name
    assert np.array_equal(s.face_instance, np.array([o.instance_id for o in s.objects], np.uint16)[s.face_object])
    assert len({o.name for o in s.objects}) == len(s.objects)


def test_repeated_assets_are_instanced(default_spec, default_scene):
    uses: dict[str, int] = {}
    for o in default_scene.objects:
        uses[o.prototype] = uses.get(o.prototype, 0) + 1
    # cars and people: at most the library's variants (assets.variants, issue 29), still shared by many
    limit = {"car": default_spec.assets.variants.car, "person": default_spec.assets.variants.person}
    for kind in ("car", "person", "lamp_post", "tree"):
        objs = [o for o in default_scene.objects if o.kind == kind]
        assert len({o.prototype for o in objs}) <= limit.get(kind, 12) < len(objs), kind
    for kind in ("building", "fence", "hedge"):
        assert all(uses[o.prototype] == 1 for o in default_scene.objects if o.kind == kind), kind


# -- where things stand -----------------------------------------------------------------------
def test_no_building_or_parked_car_overlaps_a_driving_lane(default_spec, default_scene):
    grid = make_grid(default_spec)
    r = grid.road_half
    squares = [(x - r, y - r, x + r, y + r) for x, y in (grid.node_xy(n) for n in grid.nodes)]
    lanes = _rect_boxes([rect for *_, rect in grid.lane_rects()] + squares)
    objs = [o for o in default_scene.objects
            if o.kind == "building" or (o.kind in ("car", "truck") and o.attrs.get("placement") == "parked")]
    assert any(o.kind == "car" for o in objs) and any(o.kind == "building" for o in objs)
    assert not boxes_overlap(_obj_boxes(objs, shrink=0.005), lanes).any()


def test_buildings_stay_off_streets_and_sidewalks(default_spec, default_scene):
    grid = make_grid(default_spec)
    c = grid.corridor_half
    x0, y0, x1, y1 = grid.corridor_rect
    corridors = [(x0, y - c, x1, y + c) for y in grid.ys] + [(x - c, y0, x + c, y1) for x in grid.xs]
    objs = default_scene.objects_of("building")
    assert not boxes_overlap(_obj_boxes(objs, shrink=0.005), _rect_boxes(corridors)).any()


def test_vehicles_only_in_parking_strips_or_lanes(default_spec, default_scene):
    vehicles = check_vehicles(default_spec, default_scene)
    assert len(vehicles) > 20
    if default_spec.traffic.enabled:  # traffic on: nothing stands in a lane
        assert all(o.attrs.get("placement") == "parked" for o in vehicles)
    else:
        assert any(o.kind == "truck" for o in vehicles)


def test_objects_rest_on_their_ground(default_spec, default_scene):
    ground = _check_rest(default_spec, default_scene)
    assert {round(float(g), 3) for g in ground} == {0.0, default_spec.town.curb_height_m}


def _check_rest(spec, scene) -> np.ndarray:
    grid = make_grid(spec)
    things = [o for o in scene.objects if o.instance_id > 0]
    ground = grid.ground_height(np.array([o.transform[:2, 3] for o in things]))    # where it stands
    low = np.array([_world_vertices(scene, o)[:, 2].min() for o in things])
    bad = [(o.name, float(z), float(g)) for o, z, g in zip(things, low, ground, strict=False) if abs(z - g) > 0.01]
    assert not bad
    return ground


UNUSUAL = {
    "two_lanes_no_parking": {"blocks_x": 2, "blocks_y": 1, "lanes_per_direction": 2, "parking_strip_width_m": 0,
                             "block_size_m": 30},
    "wide_lanes_narrow_walk_no_margin": {"blocks_x": 1, "blocks_y": 2, "lanes_per_direction": 3, "lane_width_m": 5,
                                         "parking_strip_width_m": 4, "sidewalk_width_m": 1, "block_size_m": 25,
                                         "margin_m": 0},
    "tight_jittered_blocks": {"blocks_x": 2, "blocks_y": 2, "block_size_m": 20, "block_size_jitter_m": 40,
                              "lane_width_m": 2.5, "curb_height_m": 0.3, "sidewalk_width_m": 8},
}


@pytest.mark.parametrize("name", sorted(UNUSUAL))
def test_unusual_cross_sections_keep_the_invariants(name):
    """build_scene verifies its routes itself; objects still rest on the ground and vehicles stay on the road."""
    spec = parse_spec({"name": name, "seed": 3, "town": UNUSUAL[name],
                       "density": {"parked_cars_per_100m": 15, "moving_cars_per_100m": 6, "truck_fraction": 0.4}},
                      f"{name}.json")
    scene = build_scene(spec)
    _check_rest(spec, scene)
    check_vehicles(spec, scene)
    assert scene.objects_of("building") and scene.objects_of("car") and scene.objects_of("traffic_light")


def test_objects_stand_upright(default_scene):
    for o in default_scene.objects:
        R = o.transform[:3, :3]
        assert np.allclose(R[2], [0, 0, 1]) and np.allclose(R[:, 2], [0, 0, 1]), o.name


def test_nothing_collides_at_street_level(default_scene):
    """Below 1 m (where people, trunks, poles, cars and walls stand) no two things overlap."""
    s = default_scene
    boxes, names = [], []
    for o in s.objects:
        if o.instance_id == 0:
            continue
        m = s.prototypes[o.prototype]
        tri = m.vertices[m.faces]
        low = tri[tri[:, :, 2].min(1) < 1.0].reshape(-1, 3)     # every triangle reaching below 1 m
        lo, hi = low.min(0), low.max(0)
        c = apply(o.transform, ((lo + hi) / 2)[None])[0]
        boxes.append([c[0], c[1], (hi[0] - lo[0]) / 2, (hi[1] - lo[1]) / 2, o.box.yaw, 0.0, 1.0])
        names.append(o.name)
    b = np.array(boxes)
    hit = boxes_overlap(b, b)
    np.fill_diagonal(hit, False)
    pairs = [(names[i], names[j]) for i, j in zip(*np.nonzero(np.triu(hit)), strict=False)]
    assert not pairs


def test_traffic_lights_guard_every_intersection_facing_approaching_traffic(default_spec, default_scene):
    grid = make_grid(default_spec)
    lights = default_scene.objects_of("traffic_light")
    per_node = {n: 0 for n in grid.nodes}
    for o in lights:
        x, y = o.transform[:2, 3]
        node = min(grid.nodes, key=lambda n: np.hypot(*(grid.node_xy(n) - (x, y))))
        d = np.array([x, y]) - grid.node_xy(node)
        assert grid.road_half < np.abs(d).min() and np.abs(d).max() < grid.corridor_half, f"{o.name} not on a corner"
        face = o.transform[:2, 0]                       # lamps look along local +x
        arm = int(np.round(np.arctan2(face[1], face[0]) / (np.pi / 2))) % 4
        assert arm in grid.arms(node) and np.allclose(face, [np.cos(arm * np.pi / 2), np.sin(arm * np.pi / 2)])
        # the light stands on the right of the traffic coming in along that arm
        heading_in = -face
        right = np.array([heading_in[1], -heading_in[0]])
        assert d @ right > 0, o.name
        per_node[node] += 1
    assert min(per_node.values()) >= 2


def test_signs_face_the_traffic_on_their_side(default_spec, default_scene):
    grid = make_grid(default_spec)
    signs = default_scene.objects_of("traffic_sign")
    assert len(signs) >= default_spec.density.signs_per_block * 9 * 0.8
    for o in signs:
        x, y = o.transform[:2, 3]
        face = o.transform[:2, 0]
        i, j = np.argmin(np.abs(grid.xs - x)), np.argmin(np.abs(grid.ys - y))
        if abs(grid.xs[i] - x) < grid.corridor_half:            # beside a north-south street
            d = np.array([x - grid.xs[i], 0.0])
        else:
            d = np.array([0.0, y - grid.ys[j]])
        traffic = np.array([d[1], -d[0]]) / np.linalg.norm(d)   # right-hand traffic next to this sidewalk...
        traffic = -traffic                                      # ...drives with the sidewalk on its right
        assert np.allclose(face, -traffic, atol=1e-6), o.name   # the sign looks at it


def test_street_cross_section(default_spec, default_scene):
    """Sidewalks at curb height, curbs with a vertical face, markings 5 mm above the asphalt."""
    table = class_table()
    h = default_spec.town.curb_height_m
    z = default_scene.vertices[default_scene.faces][:, :, 2]
    fc = default_scene.face_class
    side = fc == table.id("sidewalk")
    assert np.allclose(z[side], h, atol=0.005)
    pits = (fc == table.id("terrain")) & (default_scene.face_material == material_table().id("soil"))
    assert pits.any() and np.allclose(z[pits], h + 0.003)
    for name in ("road_marking", "crosswalk"):
        assert np.allclose(z[fc == table.id(name)], MARK_Z_M)
    assert np.allclose(z[(fc == table.id("road")) | (fc == table.id("parking"))], 0.0)
    curb = default_scene.vertices[default_scene.faces[fc == table.id("curb")]].astype(np.float64)
    n = np.cross(curb[:, 1] - curb[:, 0], curb[:, 2] - curb[:, 0])
    assert (np.abs(n[:, 2]) < 1e-6 * np.linalg.norm(n, axis=1)).sum() > 0, "curbs need vertical faces"
    assert curb[:, :, 2].max() == pytest.approx(h, abs=1e-5)


def test_street_trees_stand_in_soil_pits(default_spec, default_scene):
    grid = make_grid(default_spec)
    s = default_scene
    soil = (s.face_material == material_table().id("soil"))
    tri = s.vertices[s.faces[soil]][:, :, :2]
    lo, hi = tri.min(1), tri.max(1)
    n_street = 0
    u0 = grid.corridor_half - grid.road_half                    # sidewalks start after the corner squares
    for o in s.objects:
        if o.kind != "tree":
            continue
        x, y = o.transform[:2, 3]
        uv = np.array([segment_frame_points(seg, [(x, y)])[0] for seg in grid.segments])
        length = np.array([seg.length for seg in grid.segments])
        if ((grid.walk_inner < np.abs(uv[:, 1])) & (np.abs(uv[:, 1]) < grid.corridor_half)
                & (uv[:, 0] > u0) & (uv[:, 0] < length - u0)).any():     # on a sidewalk
            n_street += 1
            assert ((lo <= [x, y]) & (hi >= [x, y])).all(1).any(), f"{o.name} has no pit"
    assert n_street > 50


# -- outside the ring road ----------------------------------------------------------------------
def _outer_lots(spec):
    grid = make_grid(spec)
    return grid, [lot for lot in make_lots(spec, grid) if lot.block[0] < 0]


def test_outer_lots_tile_the_band_round_the_ring_road(default_spec):
    grid, lots = _outer_lots(default_spec)
    assert grid.outer_depth == max(15.0, default_spec.town.block_size_m / 2)
    x0, y0, x1, y1 = grid.corridor_rect
    bx0, by0, bx1, by1 = grid.built_rect
    band = (bx1 - bx0) * (by1 - by0) - (x1 - x0) * (y1 - y0)
    assert sum(lot.width * lot.depth for lot in lots) == pytest.approx(band, rel=1e-9)
    corners = np.array([lot.corners_world() for lot in lots])
    assert (corners >= [bx0 - 1e-6, by0 - 1e-6]).all() and (corners <= [bx1 + 1e-6, by1 + 1e-6]).all()
    boxes = np.array([[*lot.to_world([(0.0, lot.depth / 2)])[0], lot.width / 2 - 0.01, lot.depth / 2 - 0.01,
                       lot.yaw, -1.0, 1.0] for lot in lots])
    hit = boxes_overlap(boxes, np.vstack([boxes, _rect_boxes([grid.corridor_rect])[0]]))
    hit[np.arange(len(lots)), np.arange(len(lots))] = False
    assert not hit.any(), "outer lots overlap each other or the street grid"
    # the same lot logic as inside the blocks: widths, uses, fronts
    assert min(lot.width for lot in lots) >= min(9.0, 2 * grid.corridor_half) - 1e-9
    assert {lot.use for lot in lots} >= {"building", "yard"}
    assert {f.kind for lot in lots for f in lot.front} == {"hedge", "fence"}


def test_outer_lots_face_the_ring_road(default_spec):
    """Every outer lot's front lies on the ring road's outer sidewalk edge (or, for a corner
    square, on its neighbour's side) and its depth axis points away from the town."""
    grid, lots = _outer_lots(default_spec)
    x0, y0, x1, y1 = grid.corridor_rect
    fronts = {0: (1, y0), 1: (0, x1), 2: (1, y1), 3: (0, x0)}      # side -> (axis, coordinate of the front line)
    outward = {0: (0, -1), 1: (1, 0), 2: (0, 1), 3: (-1, 0)}
    per_side = {k: 0 for k in range(4)}
    for lot in lots:
        side = lot.block[1]
        axis, coord = fronts[side]
        assert lot.origin[axis] == pytest.approx(coord), lot.index
        b = lot.to_world([(0.0, 1.0)])[0] - lot.origin
        assert np.allclose(b, outward[side]), lot.index
        per_side[side] += 1
    assert min(per_side.values()) >= 5


def test_ring_road_has_buildings_and_furniture_on_its_outer_side(default_spec, default_scene):
    grid = make_grid(default_spec)
    x0, y0, x1, y1 = grid.corridor_rect
    outside = {0: lambda x, y: y < y0, 1: lambda x, y: x > x1, 2: lambda x, y: y > y1, 3: lambda x, y: x < x0}
    for side, test in outside.items():
        n = sum(test(*o.transform[:2, 3]) for o in default_scene.objects_of("building"))
        assert n >= 5, f"side {side}: {n} buildings beyond the ring road"
    # fronts face the ring road: a building's local -y (its front) points back towards the town
    lots = {lot.index: lot for lot in make_lots(default_spec, grid) if lot.block[0] < 0}
    for o in default_scene.objects_of("building"):
        lot = lots.get(o.attrs["lot"])
        if lot is not None:
            front = -o.transform[:2, 1]
            assert np.allclose(front, lot.origin - lot.to_world([(0.0, 1.0)])[0]), o.name
    # street furniture on the outer sidewalks and cars in the outer parking strips, as on any street
    ring_outer = {(seg.index, side): {} for seg in grid.segments for side in (-1, 1)
                  if not x0 < seg.to_world(seg.length / 2, side * (grid.corridor_half + 1.0))[0][0] < x1
                  or not y0 < seg.to_world(seg.length / 2, side * (grid.corridor_half + 1.0))[0][1] < y1}
    assert len(ring_outer) == 2 * (len(grid.xs) - 1) + 2 * (len(grid.ys) - 1)
    for o in default_scene.objects:
        for seg in grid.segments:
            u, v = segment_frame_points(seg, o.box.center[:2])[0]
            key = (seg.index, int(np.sign(v)))
            if key in ring_outer and 0 < u < seg.length and grid.lane_half < abs(v) <= grid.corridor_half:
                kind = f"parked {o.kind}" if o.attrs.get("placement") == "parked" else o.kind
                ring_outer[key][kind] = ring_outer[key].get(kind, 0) + 1
    assert all(c.get("lamp_post", 0) >= 1 for c in ring_outer.values()), "a ring segment without an outer lamp"
    total = {k: sum(c.get(k, 0) for c in ring_outer.values()) for k in ("tree", "person", "traffic_sign", "parked car")}
    assert min(total.values()) >= 1, total


def _horizon(scene):
    objs = [o for o in scene.objects if o.kind == "horizon"]
    assert len(objs) == 1
    return objs[0]


def test_horizon_ground_is_a_few_flat_grass_triangles(default_spec, default_scene):
    o = _horizon(default_scene)
    mesh = default_scene.prototypes[o.prototype]
    assert o.instance_id == 0 and o.cls == "terrain" and o.proxy is None
    assert mesh.n_faces <= 32
    assert (mesh.face_class == class_table().id("terrain")).all()
    assert (mesh.face_material == material_table().id("grass")).all()
    v = _world_vertices(default_scene, o)
    assert np.allclose(v[:, 2], default_spec.town.curb_height_m)
    tri = v[mesh.faces]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    assert (n[:, 2] > 0).all(), "every triangle faces up"
    # it tiles the ring between the town bounds and its outer polygon exactly once
    grid = make_grid(default_spec)
    (bx0, by0), (bx1, by1) = grid.bounds
    outer = v[np.hypot(v[:, 0], v[:, 1]) > 1000.0][:, :2]
    outer = outer[np.argsort(np.arctan2(outer[:, 1], outer[:, 0]))]
    poly = 0.5 * np.abs(np.sum(outer[:, 0] * np.roll(outer[:, 1], -1) - np.roll(outer[:, 0], -1) * outer[:, 1]))
    assert n[:, 2].sum() / 2 == pytest.approx(poly - (bx1 - bx0) * (by1 - by0), rel=1e-9)
    g = np.random.default_rng(0)
    p = g.uniform(-outer.max(), outer.max(), (20000, 2))
    a, b, c = tri[None, :, 0, :2], tri[None, :, 1, :2], tri[None, :, 2, :2]
    cross = lambda u, w: u[..., 0] * w[..., 1] - u[..., 1] * w[..., 0]   # noqa: E731
    q = p[:, None]
    covered = ((cross(b - a, q - a) >= 0) & (cross(c - b, q - b) >= 0) & (cross(a - c, q - c) >= 0)).sum(1)
    in_town = (p[:, 0] > bx0) & (p[:, 0] < bx1) & (p[:, 1] > by0) & (p[:, 1] < by1)
    in_poly = np.all(cross(np.roll(outer, -1, 0)[None] - outer[None], p[:, None] - outer[None]) > 0, axis=1)
    assert (covered[in_town] == 0).all() and (covered[in_poly & ~in_town] == 1).all()
    assert (covered[~in_poly] == 0).all()


def test_ground_has_no_holes_out_to_the_horizon(default_spec, default_scene):
    """Seen from above, ground (stuff) covers every point of the town and every point
    within HORIZON_M of it; from every route point the ground's edge is HORIZON_M or more away
    (a camera 1.65 m up sees ground to within 0.05 degrees of the horizon)."""
    s = default_scene
    cls = s.face_class.astype(np.int64)
    ground = [class_table().id(c) for c in ("road", "road_marking", "crosswalk", "curb", "sidewalk", "parking",
                                            "terrain")]
    stuff = np.isin(cls, ground)
    grid = make_grid(default_spec)
    top, z = rasterize(s.vertices, s.faces[stuff], cls[stuff], np.asarray(grid.bounds), 2.0)
    assert (top >= 0).all(), f"{int((top < 0).sum())} holes in the town ground at 0.5 m"
    assert np.isin(np.round(z, 3), [0.0, MARK_Z_M, default_spec.town.curb_height_m,
                                    default_spec.town.curb_height_m + 0.003]).all()
    reach = float(np.hypot(*np.abs(grid.bounds).max(0))) + HORIZON_M
    far = np.array([[-reach, -reach], [reach, reach]])
    top, _ = rasterize(s.vertices, s.faces[stuff], cls[stuff], far, 0.02)
    centres = (np.stack(np.meshgrid(np.arange(top.shape[1]) + 0.5, np.arange(top.shape[0]) + 0.5), -1) / 0.02
               * [1, -1] + [-reach, reach])
    assert (top[np.hypot(centres[..., 0], centres[..., 1]) < reach] >= 0).all()
    # distance from every route sample to the ground's outer edge (a convex polygon)
    v = _world_vertices(s, _horizon(s))[:, :2]
    ring = v[np.hypot(v[:, 0], v[:, 1]) > 1000.0]
    ring = ring[np.argsort(np.arctan2(ring[:, 1], ring[:, 0]))]
    edge = np.roll(ring, -1, 0) - ring
    normal = np.stack([edge[:, 1], -edge[:, 0]], 1) / np.linalg.norm(edge, axis=1)[:, None]
    for path in s.paths:
        d = ((ring[None] - path.points[:, None, :2]) * normal[None]).sum(-1).min(1)
        assert d.min() >= HORIZON_M, path.name


# -- routes ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("which", ["test", "default"])
def test_routes_drive_on_lanes_clear_of_every_object(which, request):
    spec = request.getfixturevalue(f"{which}_spec")
    scene = request.getfixturevalue(f"{which}_scene")
    grid = make_grid(spec)
    drive = grid.drivable_rects()
    limit = spec.paths.clearance_m + EGO_HALF_WIDTH_M
    things = [o for o in scene.objects if o.instance_id > 0]
    assert len(scene.paths) >= 2
    for path in scene.paths:
        xy = path.points[:, :2]
        inside = ((xy[:, None, 0] >= drive[None, :, 0]) & (xy[:, None, 0] <= drive[None, :, 2])
                  & (xy[:, None, 1] >= drive[None, :, 1]) & (xy[:, None, 1] <= drive[None, :, 3])).any(1)
        assert inside.all(), path.name
        near = min(float(point_box_distance(xy, o.box).min()) for o in things)
        assert near >= limit, f"{path.name}: an object is {near:.2f} m from the route"


def test_route_zero_is_a_smooth_closed_loop(default_scene):
    p = default_scene.paths[0]
    assert p.closed
    step = np.linalg.norm(np.diff(np.vstack([p.points, p.points[:1]]), axis=0), axis=1)
    assert step.max() <= 1.05 and step.min() > 0.3
    assert np.allclose(np.diff(p.s), step[:-1])
    d = np.diff(np.vstack([p.points, p.points[:1]])[:, :2], axis=0)
    travel = np.arctan2(d[:, 1], d[:, 0])
    assert np.abs(np.angle(np.exp(1j * (travel - p.headings)))).max() < 0.1, "headings follow the path"
    curvature = np.abs(np.angle(np.exp(1j * np.diff(np.r_[p.headings, p.headings[0]])))) / step
    assert curvature.max() <= 1 / 5.0, "turn radius below 5 m"
    turns = np.angle(np.exp(1j * np.diff(np.r_[p.headings, p.headings[0]]))).sum()
    assert abs(abs(turns) - 2 * np.pi) < 1e-6, "a simple loop turns once around"


def test_route_zero_keeps_right(default_spec, default_scene):
    """Right-hand traffic: the street centre line is on the driver's left."""
    grid = make_grid(default_spec)
    p = default_scene.paths[0]
    left = np.stack([-np.sin(p.headings), np.cos(p.headings)], 1)
    on_street = 0
    for xy, n in zip(p.points[:, :2], left, strict=False):
        dx, dy = grid.xs - xy[0], grid.ys - xy[1]
        i, j = np.argmin(np.abs(dx)), np.argmin(np.abs(dy))
        if abs(dx[i]) < grid.lane_half and abs(dy[j]) > grid.road_half:      # on a north-south street
            assert n[0] * dx[i] > 0
            on_street += 1
        elif abs(dy[j]) < grid.lane_half and abs(dx[i]) > grid.road_half:
            assert n[1] * dy[j] > 0
            on_street += 1
    assert on_street > len(p.points) // 2


def test_frames_follow_route_zero(default_spec, default_scene):
    """Frame 0 starts on a straight leg, and every frame sits on route 0 facing along it."""
    path = default_scene.paths[0]
    frames = Rig.from_spec(default_spec, default_scene).frames(4)
    steps = [np.linalg.norm(b.T_world_ego[:2, 3] - a.T_world_ego[:2, 3]) for a, b in zip(frames, frames[1:],
                                                                                         strict=False)]
    assert np.allclose(steps, default_spec.paths.spacing_m, rtol=1e-3)
    for f in Rig.from_spec(default_spec, default_scene).frames(30, first=5):
        pos, hd = path.at(f.s)
        assert np.allclose(f.T_world_ego[:3, 3], pos[0])
        assert np.allclose(f.T_world_ego[:2, 0], [np.cos(hd[0]), np.sin(hd[0])])


# -- label proxies ----------------------------------------------------------------------------------
def test_hull_proxies_contain_their_objects_hull_class_vertices(default_scene):
    hull_cls = class_table().hull_classes
    s = default_scene
    proxied = {o.prototype for o in s.objects if o.proxy is not None}
    for o in s.objects:
        has_hull_class = bool(hull_cls[s.prototypes[o.prototype].face_class].any())
        assert (o.proxy is not None) == has_hull_class, o.name
        if o.proxy is not None:
            assert o.proxy == o.prototype
    assert len(proxied) == len(s.proxies)
    for key in proxied:
        mesh, proxy = s.prototypes[key], s.proxies[key]
        for c in np.unique(mesh.face_class[hull_cls[mesh.face_class]]):
            pts = mesh.vertices[np.unique(mesh.faces[mesh.face_class == c])]
            hull_pts = proxy.vertices[np.unique(proxy.faces[proxy.face_class == c])]
            eq = ConvexHull(hull_pts).equations
            assert (pts @ eq[:, :3].T + eq[:, 3]).max() <= 1e-6, f"{key}: class {c} pokes out of its hull"


def test_oriented_boxes_enclose_object_vertices(default_scene):
    for o in default_scene.objects[:: max(1, len(default_scene.objects) // 300)]:
        v = _world_vertices(default_scene, o)
        assert o.box.contains(v, margin=1e-6).all(), o.name


def test_box_helper_sanity():
    box = OrientedBox((0.0, 0.0, 0.5), (4.0, 2.0, 1.0), np.pi / 2)
    assert point_box_distance(np.array([[0.0, 3.0], [2.0, 0.0], [0.0, 0.0]]), box).tolist() == pytest.approx([1.0,
                                                                                                              1.0, 0.0])


def test_instance_ids_go_to_things_only(default_scene):
    """SemanticKITTI and Cityscapes panoptic conventions: things get unique ids 1..N, stuff 0."""
    table = class_table()
    ids = [o.instance_id for o in default_scene.objects if table[o.cls].thing]
    assert ids and sorted(ids) == list(range(1, len(ids) + 1))
    assert all(o.instance_id == 0 for o in default_scene.objects if not table[o.cls].thing)
    stuff_faces = ~np.array([r.thing for r in table.rows])[default_scene.face_class]
    assert (default_scene.face_instance[stuff_faces] == 0).all()
    assert {table.names[c] for c in np.unique(default_scene.face_class[default_scene.face_instance > 0])} <= {
        r.name for r in table.rows if r.thing}
