"""The city beyond the town (issue 29 item 6): outside the town, labelled, cheap, deterministic, and
drawn from its own stream so the town itself is what it was."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from generator.geometry import apply
from generator.labels import class_table
from generator.layout import assemble, build_scene
from generator.layout.ground import far_city as fc
from generator.materials import material_table
from generator.spec import parse_spec


def _far(scene):
    return [o for o in scene.objects if o.kind.startswith("far_")]


def _islands(mesh, faces):
    """(k, 2, 3) local AABBs ``(min, max)`` of the connected pieces of ``mesh``'s ``faces`` (bool mask)."""
    f = mesh.faces[faces]
    n = len(mesh.vertices)
    g = coo_matrix((np.ones(2 * len(f)), (np.r_[f[:, 0], f[:, 1]], np.r_[f[:, 1], f[:, 2]])), shape=(n, n))
    _, label = connected_components(g, directed=False)
    used = np.unique(f)
    v, lab = mesh.vertices[used], label[used]
    order = np.argsort(lab, kind="stable")
    cuts = np.flatnonzero(np.diff(lab[order])) + 1
    return np.array([(p.min(0), p.max(0)) for p in np.split(v[order], cuts)])


def test_far_city_stands_outside_the_town_with_labels(default_scene):
    far = _far(default_scene)
    first = far[0].index
    assert [o.index for o in far] == list(range(first, len(default_scene.objects))), "far city comes last"
    assert not any(o.kind.startswith("far_") for o in default_scene.objects[:first])
    (bx0, by0), (bx1, by1) = default_scene.bounds
    classes, mats = class_table(), material_table()
    materials = {"building": {"far_facade", "roof"}, "vegetation": {"leaves"}, "tree_trunk": {"bark"}}
    kinds = {"far_blocks": ("building", {"building", "vegetation"}), "far_skyline": ("building", {"building"}),
             "far_trees": ("vegetation", {"vegetation", "tree_trunk"})}
    assert {o.kind for o in far} == set(kinds)
    for o in far:
        m = default_scene.prototypes[o.prototype]
        cls, face_classes = kinds[o.kind]
        assert o.cls == cls and o.instance_id == 0 and o.attrs["lot"] is None
        assert {classes.names[c] for c in np.unique(m.face_class)} == face_classes or o.kind == "far_blocks"
        for c in face_classes:
            on = m.face_class == classes.id(c)
            assert {mats.rows[i].name for i in np.unique(m.face_material[on])} <= materials[c]
        v = apply(o.transform, m.vertices)
        assert np.allclose(o.transform[:2, 3], (v[:, :2].min(0) + v[:, :2].max(0)) / 2), "stands where it is"
        crowns = m.face_class == classes.id("vegetation")
        if crowns.any():                # solid crowns: the label proxy is the crowns themselves, no hull
            p = default_scene.proxies[o.proxy]
            assert o.proxy == o.prototype and p.n_faces == crowns.sum()
            assert np.array_equal(p.vertices[p.faces], m.vertices[m.faces[crowns]])
        else:
            assert o.proxy is None
        gap = np.maximum(np.maximum(bx0 - v[:, 0], v[:, 0] - bx1), np.maximum(by0 - v[:, 1], v[:, 1] - by1))
        assert gap.min() >= fc.TREE_LINE_M - 2.0 - fc.CROWN_R_M[1] - 1e-6, o.name
        assert np.allclose(v[:, 2].min(), default_scene.prototypes["horizon_0000"].vertices[0, 2]), "on the ground"
    # stays on the horizon ground, well inside its outer edge, and cheap for both sensors
    reach = np.abs(np.concatenate([apply(o.transform, default_scene.prototypes[o.prototype].vertices)[:, :2]
                                   for o in far])).max()
    assert reach < max(bx1, by1) + fc.REACH_M + 10.0 + fc.WALL_DEPTH_M + 1.0
    n_far = sum(default_scene.prototypes[o.prototype].n_faces for o in far)
    # (113 k round the default town: the tree line's belt of 6-lobed crowns, a tree every ~4 m, is most of it)
    assert 5_000 < n_far < 130_000 and n_far < 0.07 * len(default_scene.faces)


def test_far_city_is_a_dozen_objects_whose_boxes_keep_apart(default_scene):
    """Every Blender object costs both passes, so the far city's hundreds of buildings and parks are
    joined into a dozen objects, and their bounding boxes (so their footprints) neither overlap nor
    touch each other or the town: the town's no-touch invariants hold for them as for any object."""
    far = _far(default_scene)
    building = class_table().id("building")
    n_buildings = sum(len(_islands(m, m.face_class == building))
                      for m in (default_scene.prototypes[o.prototype] for o in far if o.kind == "far_blocks"))
    assert len(far) <= 12 and n_buildings > 500, (len(far), n_buildings)
    box = np.array([[o.box.corners_xy().min(0), o.box.corners_xy().max(0)] for o in far])    # (n, 2, 2)
    town = default_scene.bounds
    for i, a in enumerate(box):
        assert (a[0] > town[1] + 1.0).any() or (a[1] < town[0] - 1.0).any(), far[i].name
        for j in range(i + 1, len(box)):
            b = box[j]
            assert (a[0] > b[1] + 1.0).any() or (b[0] > a[1] + 1.0).any(), (far[i].name, far[j].name)


def test_far_city_closes_the_horizon_all_round(default_scene):
    """From the town's centre every compass direction (0.5 degree steps) meets a far building, and
    the skyline beyond SKYLINE_M rises higher than the blocks near the town."""
    building = class_table().id("building")
    boxes = []
    for o in _far(default_scene):
        m = default_scene.prototypes[o.prototype]
        if (m.face_class == building).any():
            boxes.append(_islands(m, m.face_class == building) + o.transform[:3, 3])    # translation only
    boxes = np.concatenate(boxes)
    lo, hi = boxes[:, 0], boxes[:, 1]
    c = default_scene.bounds.mean(0)
    az = np.deg2rad(np.arange(0, 360, 0.5))
    d = np.stack([np.cos(az), np.sin(az)], 1)[:, None]                       # (A, 1, 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        t0, t1 = (lo[None, :, :2] - c) / d, (hi[None, :, :2] - c) / d
    near, far_t = np.minimum(t0, t1).max(-1), np.maximum(t0, t1).min(-1)
    hit = (near <= far_t) & (far_t > 0)
    assert hit.any(1).all(), f"{int((~hit.any(1)).sum())} directions see no building"
    (bx0, by0), (bx1, by1) = default_scene.bounds
    mid = (lo[:, :2] + hi[:, :2]) / 2
    gap = np.maximum(np.maximum(bx0 - mid[:, 0], mid[:, 0] - bx1), np.maximum(by0 - mid[:, 1], mid[:, 1] - by1))
    height = hi[:, 2] - lo[:, 2]
    assert height[gap > fc.SKYLINE_M].max() > 60.0 > height[gap < fc.SKYLINE_M].max()


def test_far_city_is_deterministic_and_seeded():
    bounds = np.array([[-150.0, -120.0], [170.0, 140.0]])
    a, b, c = fc.far_city(7, bounds, 0.15), fc.far_city(7, bounds, 0.15), fc.far_city(8, bounds, 0.15)
    assert [k for k, _, _ in a] == [k for k, _, _ in b]
    assert all(np.array_equal(m.vertices, n.vertices) and np.array_equal(m.face_material, n.face_material)
               for (_, _, m), (_, _, n) in zip(a, b, strict=True))
    flat = [np.concatenate([m.vertices for *_, m in x]).tobytes() for x in (a, c)]
    assert flat[0] != flat[1]


def test_town_is_untouched_by_the_far_city(test_spec, test_scene, monkeypatch):
    """Without the far city the same spec builds exactly the town's objects: its draws are its own."""
    monkeypatch.setattr(assemble, "far_city", lambda *a: [])
    bare = build_scene(test_spec)
    n = len(bare.objects)
    assert n < len(test_scene.objects) and all(o.kind.startswith("far_") for o in test_scene.objects[n:])
    for o, p in zip(bare.objects, test_scene.objects[:n], strict=True):
        assert (o.name, o.kind, o.cls, o.instance_id, o.prototype, o.box, o.attrs) == \
            (p.name, p.kind, p.cls, p.instance_id, p.prototype, p.box, p.attrs)
        assert np.array_equal(o.transform, p.transform)
        assert np.array_equal(bare.prototypes[o.prototype].vertices, test_scene.prototypes[p.prototype].vertices)


@pytest.mark.parametrize("angle", [None, [62, 62]])
def test_far_city_keeps_clear_of_the_routes(root, angle):
    """Also in a town whose streets cross at an angle (the far city is mapped with it)."""
    doc = json.loads((root / "scenes" / "test_town.json").read_text())
    if angle is not None:
        doc["streets"] = {**doc.get("streets", {}), "intersection_angle_deg": angle}
    scene = build_scene(parse_spec(doc, "test_town.json"))
    far = _far(scene)
    assert far
    pts = np.concatenate([p.points[:, :2] for p in scene.paths])
    v = np.concatenate([scene.prototypes[o.prototype].vertices[:, :2] @ o.transform[:2, :2].T + o.transform[:2, 3]
                        for o in far])
    nearest = np.min(np.linalg.norm(v[::7, None] - pts[None, ::5], axis=-1))
    assert nearest > 40.0
