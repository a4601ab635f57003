"""One-way streets read right to a driver and a camera (issue 13, street variety).

What a user relies on: a signal head stands for every approach that traffic of the lane graph
really takes into a node, and for no other (a one-way street that leaves a node has no approach
there); every one-way street carries a "one way" sign facing the traffic at its entry and a
"no entry" sign facing the traffic at the node it runs to, at its exit end; those signs are
class ``traffic_sign``, stand on the sidewalk and obey the placement rules.
"""

from __future__ import annotations

import numpy as np
import pytest

from assets_procedural.catalog import build
from generator.geometry import face_normals
from generator.geometry.boxes import point_box_distance
from generator.labels import class_table
from generator.layout import build_scene
from generator.layout.network.design_vehicle import EGO_HALF_WIDTH_M
from generator.layout.network.draw import make_grid
from generator.layout.network.grid import segment_frame_points
from generator.layout.placement.street_frame import Street
from generator.materials import material_table
from generator.traffic.lanes.graph import LaneGraph
from kits.street_towns import MIX_TRAFFIC, full_spec, one_way_spec
from kits.town_checks import no_collisions

#: one-way towns: 1 and 2 lanes per direction, and the 4 x 4 mix (shared, roundabouts, closures); one town
#: of each kind (a second 1-lane one-way town, seed 1, and a second mix, seed 8, checked the same code again)
TOWNS = [("one_way", 0, 1), ("one_way", 5, 2), ("mix", 3, 1)]


def _spec(kind: str, seed: int, lanes: int):
    return one_way_spec(seed, lanes) if kind == "one_way" else full_spec(seed)


@pytest.fixture(scope="module", params=TOWNS, ids=lambda t: f"{t[0]}{t[1]}x{t[2]}")
def town(request):
    spec = _spec(*request.param)
    grid = make_grid(spec)
    assert any(grid.section(s).one_way for s in grid.segments), "the town has no one-way street to check"
    return spec, grid, build_scene(spec)


def _entering_arms(graph: LaneGraph, node) -> set[int]:
    """Arms of ``node`` some lane of the lane graph enters the node from (its connectors' first arms)."""
    return {key[1] for key in graph.connector if key[0] == node}


def _arm_of(yaw: float) -> int:
    """The arm (0 east .. 3 south) a face at ``yaw`` looks along."""
    return int(np.round(yaw / (np.pi / 2))) % 4


def test_signal_heads_face_exactly_the_approaches_traffic_takes(town):
    spec, grid, scene = town
    graph = LaneGraph(grid)
    nodes = np.array([grid.node_xy(n) for n in grid.nodes])
    heads: dict = {}
    for o in scene.objects:
        if o.kind != "traffic_light":
            continue
        xy = o.transform[:2, 3]
        node = grid.nodes[int(np.argmin(np.linalg.norm(nodes - xy, axis=1)))]
        heads.setdefault(node, []).append(_arm_of(float(np.arctan2(o.transform[1, 0], o.transform[0, 0]))))
    leaving_only = 0
    for node in grid.nodes:
        if grid.is_roundabout(node):
            assert node not in heads
            continue
        entering = _entering_arms(graph, node)
        got = heads.get(node, [])
        assert sorted(got) == sorted(set(got)), f"two heads for one approach at {node}"
        assert set(got) == entering, \
            f"node {node}: heads face arms {sorted(got)}, traffic enters from {sorted(entering)}"
        leaving_only += len(set(grid.arms(node)) - entering)
    assert leaving_only > 0, "no one-way street leaves a signalised node: the test would check nothing new"


def _face_kind(scene, o) -> str | None:
    """"one_way" / "no_entry" by the sign face the object's mesh carries (blue / red sheeting)."""
    mats = material_table()
    fm = scene.prototypes[o.prototype].face_material
    if (fm == mats.id("sign_blue")).any():
        return "one_way"
    if (fm == mats.id("sign_red")).any():
        return "no_entry"
    return None


def _signs(scene, grid):
    """(kind, segment, u, v, face heading) of every regulatory sign, in the frame of the one-way
    segment whose sidewalk it stands on (segment None when it stands on none)."""
    out = []
    for o in scene.objects:
        kind = _face_kind(scene, o)
        if kind is None:
            continue
        xy = o.transform[:2, 3]
        where = None
        for seg in grid.segments:
            u, v = segment_frame_points(seg, xy[None])[0]
            if 0.0 < u < seg.length and grid.walk_inner < abs(v) < grid.corridor_half:
                where = (seg, float(u), float(v))
        assert o.cls == "traffic_sign" and o.kind == "traffic_sign", o.name
        out.append((kind, o, where))
    return out


def test_one_way_streets_carry_one_way_signs_at_entry_and_no_entry_at_exit(town):
    """Every one-way segment: a "one way" sign within 8 m of its entry end facing the traffic that
    enters, and a "no entry" sign within 8 m of its exit end facing the drivers at the exit node
    (who look along the segment away from that node); every such sign stands on a sidewalk at curb
    height, on a one-way segment, and has its face (blue or red) looking the way it should."""
    spec, grid, scene = town
    signs = _signs(scene, grid)
    near = Street(grid).walk_u0 + 8.0
    seen = {"one_way": set(), "no_entry": set()}
    for kind, o, where in signs:
        assert where is not None, f"{o.name} stands on no sidewalk"
        seg, u, v = where
        d = grid.section(seg).one_way
        assert d, f"{o.name}: a {kind} sign on a two-way street"
        assert abs(o.transform[2, 3] - grid.curb_h) < 1e-9             # at curb height, on raised ground
        assert grid.ground_height(o.transform[:2, 3][None])[0] == grid.curb_h
        face = np.array([o.transform[0, 0], o.transform[1, 0]])       # local +x: the face's normal
        flow = d * np.array([np.cos(seg.yaw), np.sin(seg.yaw)])
        from_entry = u if d > 0 else seg.length - u
        if kind == "one_way":           # faces the oncoming traffic of its own street
            assert face @ flow < -0.999, o.name
            if from_entry < near:
                seen["one_way"].add(seg.index)
        else:                           # faces along the flow: drivers at the exit node see it
            assert face @ flow > 0.999, o.name
            if seg.length - from_entry < near:
                seen["no_entry"].add(seg.index)
    one_way = {s.index for s in grid.segments if grid.section(s).one_way}
    assert seen["one_way"] == one_way, f"entries without a one-way sign: {sorted(one_way - seen['one_way'])}"
    assert seen["no_entry"] == one_way, f"exits without a no-entry sign: {sorted(one_way - seen['no_entry'])}"


def test_the_signs_keep_every_placement_rule(town):
    """No sign on a lane or a crosswalk, none within the route clearance, none intersecting anything."""
    spec, grid, scene = town
    signs = [o for _, o, _ in _signs(scene, grid)]
    assert signs
    lanes = grid.drivable_rects()
    for o in signs:
        box = o.box
        corners = np.array([[sx * box.size[0] / 2, sy * box.size[1] / 2] for sx in (-1, 1) for sy in (-1, 1)])
        c, s = np.cos(box.yaw), np.sin(box.yaw)
        pts = corners @ np.array([[c, s], [-s, c]]) + np.asarray(box.center[:2])
        inside = (pts[:, None, 0] > lanes[None, :, 0]) & (pts[:, None, 0] < lanes[None, :, 2]) \
            & (pts[:, None, 1] > lanes[None, :, 1]) & (pts[:, None, 1] < lanes[None, :, 3])
        assert not inside.any(), f"{o.name} reaches over a lane or crosswalk"
    limit = spec.paths.clearance_m + EGO_HALF_WIDTH_M
    for path in scene.paths:
        assert min(float(point_box_distance(path.points[:, :2], o.box).min()) for o in signs) >= limit - 1e-6
    no_collisions(scene)


def test_towns_without_one_way_streets_get_no_regulatory_signs():
    spec = one_way_spec(0, plain=1, shared=1)
    scene = build_scene(spec)
    assert not [o for o in scene.objects if _face_kind(scene, o)]


def test_regulatory_sign_faces_look_plus_x_with_the_symbol_on_them():
    """The blue / red face and the white symbol look +x (the way the layout turns to the traffic),
    the symbol lies inside the plate and proud of it, and all of it is class traffic_sign."""
    mats = material_table()
    for shape, face in (("one_way", "sign_blue"), ("no_entry", "sign_red")):
        m = build("traffic_sign", np.random.default_rng(3), shape=shape)
        n = face_normals(m)
        front = m.face_material == mats.id(face)
        symbol = (m.face_material == mats.id("sign_symbol")) & (n[:, 0] > 0.999)
        assert front.any() and symbol.any() and (n[front][:, 0] > 0.999).all()
        fv = m.vertices[np.unique(m.faces[front])]
        sv = m.vertices[np.unique(m.faces[symbol])]
        assert sv[:, 0].min() > fv[:, 0].max()
        assert (sv[:, 1:].min(0) > fv[:, 1:].min(0)).all() and (sv[:, 1:].max(0) < fv[:, 1:].max(0)).all()
        plate = np.isin(m.face_material, [mats.id(face), mats.id("sign_symbol"), mats.id("sign_back")])
        assert (m.face_class[plate] == class_table().id("traffic_sign")).all()


def test_no_moving_actor_touches_a_one_way_sign():
    """With traffic and pedestrians (20 s, every 0.2 s), no vehicle, rider or pedestrian box
    overlaps the footprint of a one-way or no-entry sign (pedestrians walk round them)."""
    from generator.traffic.build import build_world
    from kits.traffic_contacts import actor_quads, footprints, touching

    spec = full_spec(3, traffic={**MIX_TRAFFIC, "pedestrians_per_100m": 3.0})
    scene = build_scene(spec)
    world = build_world(spec, scene, 20.0)
    signs = footprints([o.box for o in scene.objects if _face_kind(scene, o)])
    assert len(signs) >= 10 and sum(a.kind == "person" for a in world.actors) >= 20
    for t in np.arange(0.0, 20.0, 0.2):
        assert not touching(actor_quads(world, t),
                            signs).any(), f"an actor touches a sign at t = {t:.1f} s"
