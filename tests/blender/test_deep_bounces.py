"""Diffuse rays that have bounced see plain materials (issue 29, render cost): every opaque, unlit material
switches to a plain diffuse of its mean colour for them; camera rays, lamps, glass and the labels are untouched."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from generator.materials import material_table
from generator.weather import Lighting
from generator.world.rig import Rig

pytestmark = pytest.mark.blender


def _deep_branch(mat):
    """The Mix Shader fed by a Light Path node's Is Diffuse Ray and Ray Depth (through Math nodes), or None."""
    for node in mat.node_tree.nodes:
        if node.bl_idname != "ShaderNodeMixShader" or not node.inputs[0].is_linked:
            continue
        seen, todo = set(), [node.inputs[0].links[0].from_node]
        while todo:
            n = todo.pop()
            if n.bl_idname == "ShaderNodeLightPath":
                seen |= {link.from_socket.name for out in n.outputs for link in out.links}
            todo += [i.links[0].from_node for i in n.inputs if i.is_linked]
        if {"Is Diffuse Ray", "Ray Depth"} <= seen:
            return node
    return None


def test_opaque_unlit_materials_have_a_plain_branch_lamps_and_glass_none():
    from generator.blender import materials, session

    session.reset()
    rows = material_table().rows
    built = materials.build_materials(seed=5)
    plain = {row.name for row, mat in zip(rows, built, strict=True) if _deep_branch(mat) is not None}
    expected = {row.name for row in rows if row.emissive is None and row.transmittance == 0.0}
    assert plain == expected
    assert {"asphalt", "facade_brick", "leaves", "car_body"} <= plain
    assert not plain & {"window_glass", "car_glass", "headlight", "lamp_glass"}
    for row, mat in zip(rows, built, strict=True):      # the deep side of the mix is a diffuse BSDF
        node = _deep_branch(mat)
        if node is not None:
            assert node.inputs[2].links[0].from_node.bl_idname == "ShaderNodeBsdfDiffuse", row.name


@pytest.fixture(scope="module")
def red_bounces(test_spec, test_scene, tmp_path_factory):
    """A street view rendered as shipped and with every plain colour pure red; labels of both."""
    from generator.blender import materials
    from generator.blender.renderer import Renderer
    from generator.spec.render import load_render_config

    cfg = dataclasses.replace(load_render_config("test"), resolution=(96, 64), samples=4)
    pose = Rig.from_spec(test_spec, test_scene).frame(1).T_world_camera
    out = {}
    shipped = materials.plain_color
    for name in ("shipped", "red"):
        if name == "red":
            materials.plain_color = lambda g, row: (1.0, 0.0, 0.0)
        try:
            r = Renderer(test_scene, test_spec, cfg, tmp_path_factory.mktemp(name))
        finally:
            materials.plain_color = shipped
        r.place_camera(pose)
        r.set_conditions(Lighting("day", sun_elevation_deg=35.0, sun_azimuth_deg=150.0))
        out[name] = r.render_rgb(seed=3)[0]
        out[name + "_labels"] = r.render_labels()
    return out


def test_bounced_light_takes_the_plain_colour(red_bounces):
    """Red plain colours redden the picture (light bounced off surfaces), yet the labels stay identical."""
    a, b = red_bounces["shipped"], red_bounces["red"]
    red_share = [x[..., 0].sum() / x.sum() for x in (a, b)]
    assert red_share[1] > red_share[0] + 0.03
    la, lb = red_bounces["shipped_labels"], red_bounces["red_labels"]
    assert np.array_equal(la.class_id, lb.class_id)
    assert np.array_equal(la.instance, lb.instance)


def test_camera_rays_see_the_recipe(red_bounces):
    """Directly seen surfaces keep their own colour: with every bounce red, green and blue stay (they
    would be black if camera rays took the plain branch)."""
    b = red_bounces["red"]
    assert b[..., 1].mean() > 0.5 * red_bounces["shipped"][..., 1].mean()
    assert b[..., 2].mean() > 0.5 * red_bounces["shipped"][..., 2].mean()
