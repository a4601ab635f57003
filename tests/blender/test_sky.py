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
    sky.sun_disc = True  # only for this test (the renderer draws the sun with its lamp); the world is not kept
    scene.world["ug_params"] = ""
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


def test_a_lighting_asked_for_again_keeps_its_world_and_renders_the_same(tmp_path, test_scene, test_spec):
    """Asking for the same lighting again keeps the Blender world instead of rebuilding it, and the image
    is the one a rebuilt world gives (also after a night in between)."""
    from generator.blender.renderer import Renderer
    from generator.spec.render import load_render_config
    from generator.weather import Lighting

    r = Renderer(test_scene, test_spec, load_render_config("test"), tmp_path)
    r.place_camera(rig.Rig.from_spec(test_spec, test_scene).frame(0).T_world_camera)
    day, night = Lighting("day", sun_elevation_deg=50.0, sun_azimuth_deg=215.0), Lighting("night", lit_windows=0.3)
    images, worlds = [], []
    for light in (day, day, night, night, day):
        info = r.set_conditions(light)
        images.append(r.render_rgb(0)[0])
        worlds.append((r.bscene.world.name, r.bscene.world.node_tree.nodes[0].as_pointer(), info))
    assert worlds[1] == worlds[0] and worlds[3] == worlds[2], "the same lighting again keeps its world"
    assert worlds[4][1] != worlds[0][1], "a world left for another is rebuilt when asked for again"
    assert worlds[4][2] == worlds[0][2]
    for a, b in ((0, 1), (2, 3), (0, 4)):
        assert np.array_equal(images[a], images[b])
    assert not np.array_equal(images[0], images[2])
