"""Label passes rendered in batches (one switch of the render state for several images) are the
label passes of each image alone, and no RGB image depends on what was rendered before it.

The test town with two moving cars in front of the camera of frame 2, three image times 0.1 s
apart (the cars and the camera move between them), 96x54 pixels, label supersampling 3.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from generator.world.rig import Rig
from kits.actor_world import FRAME, car_world

RES = (96, 54)
STEPS = (0.0, 0.1, 0.2)
FIELDS = ("class_id", "instance", "real_class", "real_instance", "depth")


def _renderer(spec, scene, world, scratch):
    from generator.blender.renderer import Renderer
    from generator.spec.render import MotionBlur, load_render_config
    from generator.weather import Lighting

    cfg = dataclasses.replace(load_render_config("test"), resolution=RES, samples=4, label_supersample=3,
                              motion_blur=MotionBlur(True, 0.01))
    r = Renderer(scene, spec, cfg, scratch, world)
    r.set_conditions(Lighting("day", sun_elevation_deg=40.0, sun_azimuth_deg=150.0))
    return r


@pytest.fixture(scope="module")
def renders(tmp_path_factory, test_spec, test_scene):
    """Per image time: labels and RGB rendered the worker's way (batch of 3, then the RGBs) and
    each image alone in a fresh Renderer (labels, then its RGB)."""
    from generator.blender import session
    from generator.jobs.exposure import expose

    rig = Rig.from_spec(test_spec, test_scene)
    frame = rig.frame(FRAME)
    world = car_world(test_spec, test_scene, rig, frame.t)
    times = [frame.t + s for s in STEPS]
    scratch = tmp_path_factory.mktemp("batch")

    def pose(r, t):
        return lambda: expose(r, rig, t, frame.T_ego_camera)

    r = _renderer(test_spec, test_scene, world, scratch / "batched")
    batched = {"labels": r.render_labels_batch([pose(r, t) for t in times]), "rgb": []}
    for t in times:
        pose(r, t)()
        batched["rgb"].append(r.render_rgb(seed=3)[0])
    alone = {"labels": [], "rgb": []}
    for i, t in enumerate(times):
        session.reset()
        r = _renderer(test_spec, test_scene, world, scratch / f"alone{i}")
        pose(r, t)()
        alone["labels"].append(r.render_labels())
        alone["rgb"].append(r.render_rgb(seed=3)[0])
    session.reset()
    return batched, alone, world


@pytest.mark.blender
def test_batched_labels_equal_each_image_rendered_alone(renders):
    batched, alone, world = renders
    for b, a in zip(batched["labels"], alone["labels"], strict=False):
        for name in FIELDS:
            np.testing.assert_array_equal(getattr(b, name), getattr(a, name), err_msg=name)
    cars = {act.instance_id for act in world.actors}
    seen = [frozenset(np.unique(b.instance)) & cars for b in batched["labels"]]
    assert all(seen), "the moving cars must be in view, or the test proves nothing about poses"
    assert not np.array_equal(batched["labels"][0].instance, batched["labels"][-1].instance), \
        "the cars move between the image times: each pose must be rendered, not the first one three times"


@pytest.mark.blender
def test_rgb_does_not_depend_on_the_renders_before_it(renders):
    batched, alone, _ = renders
    for b, a in zip(batched["rgb"], alone["rgb"], strict=False):
        np.testing.assert_array_equal(b, a)


@pytest.mark.blender
def test_sky_is_labelled_sky_with_the_rgb_world_in_place(renders):
    from generator.labels import class_table

    batched, _, _ = renders
    sky = class_table().id("sky")
    for lab in batched["labels"]:
        label_sky, real_sky = lab.class_id == sky, lab.real_class == sky
        h = label_sky.shape[0]
        # the camera looks about level (pitch jitter of a few degrees) over ground reaching 2 km: no sky low down
        low = slice(2 * h // 3, None)
        assert label_sky[: h // 2].mean() > 0.05 and not label_sky[low].any() and not real_sky[low].any()
        # the 3x vote and the 1x pixel-centre pass are separate renders: they agree but at sky borders
        assert (label_sky == real_sky).mean() > 0.98
        np.testing.assert_array_equal(real_sky, np.isinf(lab.depth))
        assert (lab.instance[label_sky] == 0).all() and (lab.real_instance[real_sky] == 0).all()
