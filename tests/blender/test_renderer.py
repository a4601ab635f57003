"""Blender edge on hand-made scenes: label proxies, exact labels, same geometry as the SceneModel."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from generator.labels import class_table
from generator.weather import Lighting
from generator.world import rig
from kits.scene_kit import fence_scene

pytestmark = pytest.mark.blender

FENCE, BUILDING = class_table().id("fence"), class_table().id("building")


@pytest.fixture(scope="module")
def fence_render(tmp_path_factory, test_spec):
    from generator.blender.renderer import Renderer
    from generator.spec.render import load_render_config

    cfg = dataclasses.replace(load_render_config("test"), resolution=(192, 108), samples=4)
    scene = fence_scene()
    r = Renderer(scene, test_spec, cfg, tmp_path_factory.mktemp("scratch"))
    r.set_conditions(Lighting("day", sun_elevation_deg=45.0, sun_azimuth_deg=200.0))
    T = rig.camera_extrinsics((0.0, 0.0, 1.0), (0, 0, 0))
    out = r.render(T, seed=0, light_info={})
    return r, scene, out


def test_fence_mask_is_solid_while_rgb_sees_the_building_between_bars(fence_render):
    _, _, out = fence_render
    lab = out.labels
    fence_px = lab.class_id == FENCE
    assert fence_px.sum() > 200
    # Inside the fence's mask the real surface alternates between bars and the building behind.
    real_in_mask = lab.real_class[fence_px]
    gaps = fence_px & (lab.real_class == BUILDING)
    bars = fence_px & (lab.real_class == FENCE)
    assert gaps.sum() > 0.3 * fence_px.sum(), "the hull should cover the gaps between bars"
    assert bars.sum() > 0.05 * fence_px.sum()
    assert set(np.unique(real_in_mask)) <= {FENCE, BUILDING, class_table().id("road")}
    # Through the gaps the camera sees the wall at 12 m; on the bars the fence at ~6 m.
    assert np.median(lab.depth[gaps]) == pytest.approx(12.0, rel=0.15)
    assert np.median(lab.depth[bars]) < 8.0
    # The RGB pass does not render the hull: gap pixels look like the wall above the fence, not like bars.
    wall_above = (lab.class_id == BUILDING) & (lab.real_class == BUILDING)
    c_gap, c_bar, c_wall = (out.rgb[m].mean(0) for m in (gaps, bars, wall_above))
    assert np.linalg.norm(c_gap - c_wall) < np.linalg.norm(c_gap - c_bar)


def test_labels_are_exact_and_cover_the_image(fence_render):
    _, _, out = fence_render
    cls = out.labels.class_id
    assert cls.dtype == np.uint8 and cls.max() < len(class_table())
    masks = np.stack([cls == i for i in range(len(class_table()))])
    assert (masks.sum(0) == 1).all()
    assert set(np.unique(out.labels.instance)) <= {0, 1, 2}


def test_blender_geometry_equals_scene_model(fence_render):
    r, scene, _ = fence_render
    n, bounds = r.evaluated_geometry()
    assert n == len(scene.faces)
    v = scene.vertices
    assert np.allclose(bounds, np.stack([v.min(0), v.max(0)]), atol=1e-4)


def test_same_pose_gives_identical_labels(fence_render):
    r, _, out = fence_render
    again = r.render(rig.camera_extrinsics((0.0, 0.0, 1.0), (0, 0, 0)), seed=0, light_info={})
    assert np.array_equal(again.labels.class_id, out.labels.class_id)
    assert np.array_equal(again.labels.instance, out.labels.instance)
    assert np.array_equal(again.labels.depth, out.labels.depth)
