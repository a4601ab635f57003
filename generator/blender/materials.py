"""Blender materials: one procedural material per row of the material table, and the
label-pass override (sky needs no label world: it is where the Z pass reports no hit).

The label override is one emission material for every object: colour
``(class_id, instance_id, 0)`` from the per-face ``class_id`` attribute and the object
pass index, strength 1, no light sampling. Rendered with 1 sample and a box filter of
minimal width, each pixel holds exactly those integers (float32 is exact below 2**24).
"""

from __future__ import annotations

import logging

from generator.blender import recipes, recipes_actors, recipes_far, recipes_look, recipes_street
from generator.blender.bpy_guard import bpy
from generator.blender.nodes import Nodes
from generator.materials import material_table
from generator.rng import stream

log = logging.getLogger(__name__)

LABEL_MATERIAL = "urbangen_label"


def build_materials(seed: int) -> list[bpy.types.Material]:
    """Create the material of every material id; index the result with a material id.

    Parameters
    ----------
    seed : int
        The spec's seed; each material draws its parameters from ``stream(seed, "materials", name)``.
    """
    out = []
    for row in material_table().rows:
        modules = (recipes, recipes_actors, recipes_look, recipes_street, recipes_far)
        recipe = next((getattr(m, row.name) for m in modules if hasattr(m, row.name)), None)
        if recipe is None:
            raise RuntimeError(f"no Blender recipe for material {row.name!r} (generator/blender/recipes*.py)")
        mat = bpy.data.materials.new(row.name)
        g = Nodes(mat.node_tree)
        g.output(recipe(g, stream(seed, "materials", row.name)))
        if row.emissive is not None:
            # Emission strength follows scene switches (day/night); Cycles would estimate it for
            # its light tree once and keep the estimate with persistent data, so a render would
            # depend on the renders before it. Lamps light the scene through real lights instead.
            mat.cycles.emission_sampling = "NONE"
        out.append(mat)
    return out


def label_material() -> bpy.types.Material:
    """The label-pass override material (created once)."""
    mat = bpy.data.materials.get(LABEL_MATERIAL)
    if mat is not None:
        return mat
    mat = bpy.data.materials.new(LABEL_MATERIAL)
    g = Nodes(mat.node_tree)
    comb = g.node("ShaderNodeCombineXYZ")
    g.set(comb.inputs[0], g.attr("class_id"))
    g.set(comb.inputs[1], g.object_info("Object Index"))
    g.output(g.emission(comb.outputs[0], 1.0))
    mat.cycles.emission_sampling = "NONE"
    return mat
