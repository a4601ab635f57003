"""The wet shader keeps its look: soaked ground turns into a sky mirror, walls are untouched, and
a new puddle seed moves the puddles."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from generator.labels import class_table
from generator.weather import Lighting
from generator.world.rig import Rig

pytestmark = pytest.mark.blender

ROAD, BUILDING = class_table().id("road"), class_table().id("building")


@pytest.fixture(scope="module")
def wet_renders(test_spec, test_scene, tmp_path_factory):
    from generator.blender.renderer import Renderer
    from generator.spec.render import load_render_config

    cfg = dataclasses.replace(load_render_config("test"), resolution=(160, 96), samples=4)
    r = Renderer(test_scene, test_spec, cfg, tmp_path_factory.mktemp("wet"))
    r.place_camera(Rig.from_spec(test_spec, test_scene).frame(1).T_world_camera)
    light = Lighting("day", sun_elevation_deg=35.0, sun_azimuth_deg=150.0)
    out = {}
    for name, wetness, seed in (("dry", 0.0, 0.0), ("wet", 1.0, 11.0), ("wet_other_seed", 1.0, 517.0)):
        r.set_conditions(light, wetness, seed)
        out[name] = r.render_rgb(seed=3)[0]
    out["labels"] = r.render_labels()
    return out


def test_soaked_ground_mirrors_the_sky_and_walls_do_not_change(wet_renders):
    cls = wet_renders["labels"].real_class
    road, wall = cls == ROAD, cls == BUILDING
    assert road.sum() > 500 and wall.sum() > 200
    lum = {k: wet_renders[k].mean(-1) for k in ("dry", "wet")}
    # soaked asphalt (roughness 0.08): its darker albedo is outshone by the sky it now mirrors
    assert lum["wet"][road].mean() > 1.5 * lum["dry"][road].mean()
    sky_tint = wet_renders["wet"][road].mean(0)
    assert sky_tint[2] > sky_tint[0]  # the reflection is sky blue
    assert abs(lum["wet"][wall].mean() / lum["dry"][wall].mean() - 1) < 0.05


def test_puddle_seed_moves_the_puddles(wet_renders):
    road = wet_renders["labels"].real_class == ROAD
    a, b = wet_renders["wet"][road], wet_renders["wet_other_seed"][road]
    assert np.abs(a - b).mean() > 0.02 * a.mean()
