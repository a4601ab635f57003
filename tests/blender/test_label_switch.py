"""The label pass through the label switch inside every material is the label pass of the old
view-layer override, and the switch costs the RGB pass nothing it renders.

The test town from the test spec's first camera pose, 96x54 pixels, label supersampling 1.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from generator.world.rig import Rig

RES = (96, 54)


@pytest.fixture(scope="module")
def renderer(tmp_path_factory, test_spec, test_scene):
    from generator.blender import session
    from generator.blender.renderer import Renderer
    from generator.spec.render import load_render_config
    from generator.weather import Lighting

    cfg = dataclasses.replace(load_render_config("test"), resolution=RES, samples=2, label_supersample=1)
    r = Renderer(test_scene, test_spec, cfg, tmp_path_factory.mktemp("switch"))
    r.set_conditions(Lighting("day", sun_elevation_deg=40.0, sun_azimuth_deg=150.0))
    r.place_camera(Rig.from_spec(test_spec, test_scene).frame(0).T_world_camera)
    yield r
    session.reset()


@pytest.mark.blender
def test_every_material_mixes_its_surface_with_the_label_on_the_switch(renderer):
    from generator.blender import controls

    for mat in renderer.materials:
        out = next(n for n in mat.node_tree.nodes if n.bl_idname == "ShaderNodeOutputMaterial")
        mix = out.inputs[0].links[0].from_node
        assert mix.bl_idname == "ShaderNodeMixShader", mat.name
        fac = mix.inputs[0].links[0].from_node
        assert (fac.attribute_type, fac.attribute_name) == ("VIEW_LAYER", controls.LABEL), mat.name
        assert mat.cycles.emission_sampling == "NONE", mat.name


@pytest.mark.blender
def test_switch_labels_equal_the_override_labels(renderer):
    from generator.blender import geometry, passes, session
    from generator.blender.materials import label_material

    r = renderer
    rgb_before = r.render_rgb(seed=1)[0]
    lab = r.render_labels()
    assert r.bscene.view_layers[0].material_override is None
    session.label_state(r.bscene, label_material())
    geometry.set_proxies_visible(r.handles, True)
    cls, inst = passes.label_samples(passes._render(r.bscene, r.scratch / "override.exr"))
    geometry.set_proxies_visible(r.handles, False)
    assert len(np.unique(lab.class_id)) > 3, "the view must hold several classes, or the test proves little"
    np.testing.assert_array_equal(lab.class_id, cls)
    np.testing.assert_array_equal(lab.instance, inst)
    np.testing.assert_array_equal(r.render_rgb(seed=1)[0], rgb_before)
