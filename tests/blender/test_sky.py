"""By day the sky's sun and the sun lamp agree: shadows are consistent with the sky (Blender)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import OpenEXR
import pytest

from generator.world import rig

pytestmark = pytest.mark.blender


@pytest.mark.parametrize("elevation,azimuth", [(30.0, 0.0), (30.0, 90.0), (20.0, 225.0), (45.0, 300.0)])
def test_sky_sun_disc_is_where_the_lamp_light_comes_from(tmp_path, elevation, azimuth):
    from generator.blender import camera, lighting, session
    from generator.blender.bpy_guard import bpy
    from generator.spec.render import load_render_config

    scene = session.reset()
    cfg = dataclasses.replace(load_render_config("test"), resolution=(61, 61), samples=1)
    session.configure(scene, cfg)
    session.rgb_state(scene, cfg, 0)
    lighting.day_world(scene, lighting.DayLight(elevation, azimuth))
    sky = next(n for n in scene.world.node_tree.nodes if n.bl_idname == "ShaderNodeTexSky")
    sky.sun_disc = True  # only for this test: the renderer draws the sun with its lamp
    d = lighting.sun_direction(elevation, azimuth)
    lamp = bpy.data.objects["urbangen_sun"]
    bpy.context.view_layer.update()
    assert np.allclose(np.array(lamp.matrix_world)[:3, 2], d, atol=1e-6), "a sun lamp shines along its -z"
    look = rig.camera_extrinsics((0, 0, 0), (0, 0, 0), (math.atan2(d[1], d[0]), -math.asin(d[2]), 0.0))
    camera.place(scene, look, 40.0)
    bpy.ops.render.render()
    path = tmp_path / "sky.exr"
    bpy.data.images["Render Result"].save_render(str(path))
    with OpenEXR.File(str(path)) as f:
        px = np.array(f.parts[0].channels["ViewLayer.Combined"].pixels)[..., :3].sum(-1)
    r, c = np.unravel_index(np.argmax(px), px.shape)
    assert abs(r - 30) <= 1 and abs(c - 30) <= 1, (r, c)
