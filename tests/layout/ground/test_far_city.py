"""The city beyond the town (issue 29 item 6): outside the town, labelled, cheap, deterministic, and
drawn from its own stream so the town itself is what it was."""

from __future__ import annotations

import json

import numpy as np
import pytest

from generator.geometry import apply
from generator.labels import class_table
from generator.layout import assemble, build_scene
from generator.layout.ground import far_city as fc
from generator.materials import material_table
from generator.spec import parse_spec


def _far(scene):
    return [o for o in scene.objects if o.kind.startswith("far_")]


def test_far_city_stands_outside_the_town_with_labels(default_scene):
    far = _far(default_scene)
    first = far[0].index
    assert [o.index for o in far] == list(range(first, len(default_scene.objects))), "far city comes last"
    assert not any(o.kind.startswith("far_") for o in default_scene.objects[:first])
    (bx0, by0), (bx1, by1) = default_scene.bounds
    classes, mats = class_table(), material_table()
    kinds = {"far_block": ("building", {"far_facade", "roof"}), "far_park": ("vegetation", {"leaves"}),
             "far_trees": ("vegetation", {"leaves"})}
    for o in far:
        m = default_scene.prototypes[o.prototype]
        cls, materials = kinds[o.kind]
        assert o.cls == cls and o.instance_id == 0 and o.attrs["lot"] is None
        assert (m.face_class == classes.id(cls)).all()
        assert {mats.rows[i].name for i in np.unique(m.face_material)} <= materials
        v = apply(o.transform, m.vertices)
        assert np.allclose(o.transform[:2, 3], (v[:, :2].min(0) + v[:, :2].max(0)) / 2), "stands where it is"
        if cls == "vegetation":         # solid crowns: the label proxy is the crowns themselves, no hull
            assert o.proxy == o.prototype and default_scene.proxies[o.proxy] is m
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
    assert 5_000 < n_far < 60_000 and n_far < 0.05 * len(default_scene.faces)


def test_far_city_closes_the_horizon_all_round(default_scene):
    """From the town's centre every compass direction (0.5 degree steps) meets a far building, and
    the skyline beyond SKYLINE_M rises higher than the blocks near the town."""
    far = [o for o in _far(default_scene) if o.kind == "far_block"]
    verts = [apply(o.transform, default_scene.prototypes[o.prototype].vertices) for o in far]
    lo = np.array([v.min(0) for v in verts])
    hi = np.array([v.max(0) for v in verts])
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
