"""Blender materials: one procedural material per row of the material table, each carrying the
label pass inside it (sky needs no label world: it is where the Z pass reports no hit).

The label surface is an emission of colour ``(class_id, instance_id, 0)`` from the per-face
``class_id`` attribute and the object pass index, strength 1, no light sampling. Every
material ends in a Mix Shader between its own surface (factor 0) and that label emission
(factor 1), the factor read from the scene switch :data:`generator.blender.controls.LABEL`.
Rendered with 1 sample and a box filter of minimal width, each label pixel holds exactly those
integers (float32 is exact below 2**24); with the switch at 0 the RGB pass renders the same
bytes as the recipe alone. A switch rather than the view layer's material override: Cycles
recompiles every shader and re-syncs every mesh when the override changes (about 0.5 s a
switch at the preview preset, twice a frame), while a view-layer attribute only re-evaluates.
:func:`label_material` is the same label surface as a material of its own (benches compare
against the override).
"""

from __future__ import annotations

import logging

from generator.blender import controls, recipes, recipes_actors, recipes_far, recipes_look, recipes_street
from generator.blender.bpy_guard import bpy
from generator.blender.nodes import Nodes
from generator.materials import material_table, srgb_to_linear
from generator.rng import stream

log = logging.getLogger(__name__)

LABEL_MATERIAL = "urbangen_label"

#: A diffuse ray that has bounced this many times (None: never) sees every opaque, unlit material as a
#: plain diffuse of its mean colour (:func:`plain_color`) instead of its full recipe. Light reflected
#: diffusely off a surface carries its mean colour, not its cracks, bricks or leaf veins, and the detailed
#: shaders evaluated at every bounce were a large share of the paper preset's render time. Camera rays,
#: reflections and refraction (glossy and transmission rays), lamps and glass keep their recipes; the
#: label pass (no bounces) is unchanged, and no geometry is cut (shadows and LiDAR unchanged).
DEEP_DIFFUSE_BOUNCES: int | None = 1
#: Materials whose colour is the object's colour (``Object.color``: paint, signs, clothes), and those
#: whose table colour the object's colour tints (rendered facades, balconies).
OBJECT_COLOURED = frozenset({"car_paint", "car_body", "truck_paint", "sign_face", "clothing", "clothing_bottom"})
OBJECT_TINTED = frozenset({"facade_plaster", "balcony_metal"})


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
        surface = recipe(g, stream(seed, "materials", row.name))
        if DEEP_DIFFUSE_BOUNCES is not None and row.emissive is None and row.transmittance == 0.0:
            surface = plain_when_deep(g, surface, plain_color(g, row), DEEP_DIFFUSE_BOUNCES)
        g.output(g.mix_shader(g.attr(controls.LABEL, "VIEW_LAYER"), surface, label_surface(g)))
        # Emission strength follows scene switches (day/night, the label switch); Cycles would
        # estimate it for its light tree once and keep the estimate with persistent data, so a
        # render would depend on the renders before it (and every label emission would be a
        # mesh light). Lamps light the scene through real lights instead.
        mat.cycles.emission_sampling = "NONE"
        out.append(mat)
    return out


def plain_when_deep(g: Nodes, surface, color, bounces: int):
    """``surface``, but a diffuse of ``color`` for diffuse rays that have bounced ``bounces`` times or more
    (Cycles evaluates only the branch of the Mix Shader a ray takes)."""
    path = g.node("ShaderNodeLightPath").outputs
    deep = g.mul(path["Is Diffuse Ray"], g.math("GREATER_THAN", path["Ray Depth"], bounces - 0.5))
    plain = g.node("ShaderNodeBsdfDiffuse")
    g.set(plain.inputs["Color"], color)
    return g.mix_shader(deep, surface, plain.outputs[0])


def plain_color(g: Nodes, row):
    """The mean colour of material ``row`` (linear): its table colour, or the object's colour
    (:data:`OBJECT_COLOURED`), or the table colour tinted by it (:data:`OBJECT_TINTED`)."""
    table = tuple(float(c) for c in srgb_to_linear(row.color))
    if row.name in OBJECT_COLOURED:
        return g.object_info("Color")
    if row.name in OBJECT_TINTED:
        return g.mix(1.0, table, g.object_info("Color"), "MULTIPLY")
    return table


def label_surface(g: Nodes):
    """The label emission: colour (class_id, instance id, 0), strength 1 (a shader socket)."""
    comb = g.node("ShaderNodeCombineXYZ")
    g.set(comb.inputs[0], g.attr("class_id"))
    g.set(comb.inputs[1], g.object_info("Object Index"))
    return g.emission(comb.outputs[0], 1.0)


def label_material() -> bpy.types.Material:
    """The label surface as a material of its own, for a view-layer override (created once)."""
    mat = bpy.data.materials.get(LABEL_MATERIAL)
    if mat is not None:
        return mat
    mat = bpy.data.materials.new(LABEL_MATERIAL)
    g = Nodes(mat.node_tree)
    g.output(label_surface(g))
    mat.cycles.emission_sampling = "NONE"
    return mat
