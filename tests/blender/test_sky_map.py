"""The render config's ``sky_map_resolution``: the world's importance map that size, the picture the same (Blender)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from generator.weather import Lighting
from generator.world.rig import Rig

pytestmark = pytest.mark.blender

DAY = Lighting("day", sun_elevation_deg=35.0, sun_azimuth_deg=150.0, cloud_cover=0.5)


def _renderer(test_scene, test_spec, tmp_path, resolution):
    from generator.blender.renderer import Renderer
    from generator.spec.render import load_render_config

    cfg = dataclasses.replace(load_render_config("test"), sky_map_resolution=resolution, samples=4)
    r = Renderer(test_scene, test_spec, cfg, tmp_path)
    r.place_camera(Rig.from_spec(test_spec, test_scene).frame(0).T_world_camera)
    return r


def test_every_world_gets_the_configured_map_and_the_image_stays_the_same(test_scene, test_spec, tmp_path):
    from generator.blender.bpy_guard import bpy

    images = {}
    for res in (0, 128):
        r = _renderer(test_scene, test_spec, tmp_path / str(res), res)
        for light in (Lighting("night", lit_windows=0.5), DAY):  # both worlds, the day one last
            r.set_conditions(light)
            w = bpy.context.scene.world.cycles
            assert (w.sampling_method, w.sample_map_resolution if res else 0) == (
                ("MANUAL", res) if res else ("AUTOMATIC", 0)), (res, light.time_of_day)
        images[res] = r.render_rgb(seed=3)[0]
        if res == 0:
            other_seed = r.render_rgb(seed=4)[0]
    a, b = images[0], images[128]
    # the same random numbers, only the sky's sampling differs: far closer than two seeds' noise
    assert a.mean() > 0.02 and np.abs(a - b).mean() < 0.1 * np.abs(a - other_seed).mean()
