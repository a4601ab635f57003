"""Facade shading (issue 29 item 5) in Blender: the wall, trim and glass node trees are whole, a wall
seen from across the street shows its material's pattern, and lit windows still glow at night."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from generator.labels import class_table
from generator.weather import Lighting
from kits.camera_kit import look_at

pytestmark = pytest.mark.blender

BUILDING = class_table().id("building")
FACADE_MATERIALS = ("facade_plaster", "facade_brick", "facade_concrete", "facade_trim", "drainpipe", "window_glass",
                    "shop_glass", "shop_sign")




@pytest.fixture(scope="module")
def facade(test_spec, test_scene, tmp_path_factory):
    """Renders of the first building of the test town whose front fills most of a view from 7 m."""
    from generator.blender.renderer import Renderer
    from generator.spec.render import load_render_config

    cfg = dataclasses.replace(load_render_config("test"), resolution=(96, 72), samples=4)
    r = Renderer(test_scene, test_spec, cfg, tmp_path_factory.mktemp("facade"))
    for o in test_scene.objects:
        if o.kind != "building":
            continue
        T = o.transform
        lo, hi = test_scene.prototypes[o.prototype].bounds()
        centre = T[:3, :3] @ np.array([(lo[0] + hi[0]) / 2, lo[1], 0.0]) + T[:3, 3]
        front = T[:3, :3] @ np.array([0.0, -1.0, 0.0])
        eye = centre + 7.0 * front + [0.0, 0.0, 1.7]
        r.place_camera(look_at(eye, centre + [0.0, 0.0, 4.0]))
        labels = r.render_labels()
        wall = labels.class_id == BUILDING
        if wall.mean() > 0.6:
            break
    else:
        pytest.fail("no building front fills a view in the test town")
    out = {"wall": wall, "facade": o.attrs["facade"]}
    for name, light in (("day", Lighting("day", sun_elevation_deg=40.0, sun_azimuth_deg=200.0)),
                        ("lit", Lighting("night", lit_windows=1.0)), ("dark", Lighting("night", lit_windows=0.0))):
        r.set_conditions(light)
        out[name] = r.render_rgb(seed=3)[0]
    from generator.blender.bpy_guard import bpy
    out["broken"] = [m.name for m in bpy.data.materials if m.name in FACADE_MATERIALS
                     and not all(link.is_valid for link in m.node_tree.links)]
    out["unlinked"] = [m.name for m in bpy.data.materials if m.name in FACADE_MATERIALS
                       and not any(n.bl_idname == "ShaderNodeOutputMaterial" and n.inputs[0].is_linked
                                   for n in m.node_tree.nodes)]
    return out


def test_facade_node_trees_are_whole(facade):
    assert facade["broken"] == [] and facade["unlinked"] == []


def test_a_wall_from_across_the_street_is_not_one_flat_colour(facade):
    """Day: the wall's pixels spread in brightness (joints, grain, stains, trim, shadowed reveals), and
    are neither black nor blown out."""
    lum = facade["day"][facade["wall"]] @ np.array([0.2126, 0.7152, 0.0722])
    assert 0.01 < np.median(lum) < 5.0
    assert np.percentile(lum, 90) > 1.5 * np.percentile(lum, 10)


def test_lit_windows_still_glow_at_night(facade):
    wall = facade["wall"]
    lit, dark = facade["lit"][wall].mean(), facade["dark"][wall].mean()
    assert lit > 2.0 * dark > 0.0        # night radiance is dim (real units): ~3e-4 lit, ~8e-5 dark here
