"""The licence plate's shader: frame, EU band and the car's own registration, from the glyph atlas.

The plate is drawn in its millimetres (:data:`generator.blender.plates.PLATE_MM`), read from the mesh's
``ug_plate`` UV map (:func:`generator.blender.plates.plate_uv`); the characters are the object's
``ug_plate_0 .. ug_plate_9`` glyph codes, shifted right by ``ug_plate_off`` cells
(:func:`generator.blender.plates.apply_plates`), each sampled from one packed image (:func:`glyph_image`).
About 60 math nodes and one image lookup, evaluated only on the plates' faces.
"""

from __future__ import annotations

import numpy as np

from generator.blender import plates as pl
from generator.blender.bpy_guard import bpy
from generator.blender.nodes import Nodes

ATLAS = "ug_plate_glyphs"   #: name of the packed glyph image


def glyph_image() -> bpy.types.Image:
    """The packed glyph atlas (:func:`generator.blender.plates.glyph_atlas`); made once per Blender session,
    linear values (``Non-Color``), colour and alpha independent (``CHANNEL_PACKED``)."""
    img = bpy.data.images.get(ATLAS)
    if img is not None:
        return img
    atlas = pl.glyph_atlas()
    h, w = atlas.shape[:2]
    img = bpy.data.images.new(ATLAS, w, h, alpha=True, float_buffer=True)
    img.colorspace_settings.name = "Non-Color"
    img.alpha_mode = "CHANNEL_PACKED"
    img.pixels.foreach_set(np.ascontiguousarray(atlas[::-1]).ravel())   # Blender's rows start at the bottom
    img.pack()
    return img


def _between(g: Nodes, x, lo: float, hi: float):
    """1 where ``lo < x < hi``, else 0."""
    return g.mul(g.math("GREATER_THAN", x, lo), g.math("LESS_THAN", x, hi))


def _text_code(g: Nodes, cell):
    """The glyph code of character cell ``cell`` (0 blank outside the cells)."""
    code = 0.0
    for i in range(pl.N_CELLS):
        eq = g.node("ShaderNodeMath", operation="COMPARE")
        g.set(eq.inputs[0], cell)
        eq.inputs[1].default_value, eq.inputs[2].default_value = float(i), 0.25
        code = g.add(code, g.mul(eq.outputs[0], g.attr(f"ug_plate_{i}", "OBJECT", "Fac")))
    return code


def plate_surface(g: Nodes, background, roughness: float = 0.35):
    """The plate's Principled BSDF over ``background`` (its colour: white or yellow)."""
    uv = g.node("ShaderNodeUVMap", uv_map="ug_plate").outputs["UV"]
    sep = g.node("ShaderNodeSeparateXYZ")
    g.set(sep.inputs[0], uv)
    x, y = g.mul(sep.outputs["X"], pl.PLATE_MM[0]), g.mul(sep.outputs["Y"], pl.PLATE_MM[1])
    inner = g.mul(_between(g, x, pl.FRAME_MM, pl.PLATE_MM[0] - pl.FRAME_MM),
                  _between(g, y, pl.FRAME_MM, pl.PLATE_MM[1] - pl.FRAME_MM))
    t = g.math("DIVIDE", g.math("SUBTRACT", y, pl.INNER_MM[0]), pl.INNER_MM[1] - pl.INNER_MM[0])
    band = g.math("LESS_THAN", x, pl.BAND_MM[1])
    cellf = g.math("SUBTRACT", g.math("DIVIDE", g.math("SUBTRACT", x, pl.TEXT_X0_MM), pl.CELL_MM),
                   g.attr("ug_plate_off", "OBJECT", "Fac"))
    cell = g.math("FLOOR", cellf)
    s = g.lerp(band, g.math("SUBTRACT", cellf, cell),
               g.math("DIVIDE", g.math("SUBTRACT", x, pl.BAND_MM[0]), pl.BAND_MM[1] - pl.BAND_MM[0]))
    code = g.lerp(band, _text_code(g, cell), float(pl.BAND_CODE))
    s = g.math("MINIMUM", g.math("MAXIMUM", s, 0.01), 0.99)            # stay inside the cell (no bleeding)
    t = g.math("MINIMUM", g.math("MAXIMUM", t, 0.005), 0.995)
    vec = g.node("ShaderNodeCombineXYZ")
    g.set(vec.inputs["X"], g.math("DIVIDE", g.add(code, s), float(pl.BAND_CODE + 1)))
    g.set(vec.inputs["Y"], t)
    tex = g.node("ShaderNodeTexImage", image=glyph_image(), interpolation="Linear", extension="EXTEND")
    g.set(tex.inputs["Vector"], vec.outputs[0])
    ink = g.mul(tex.outputs["Alpha"], inner)
    color = g.mix(ink, background, tex.outputs["Color"])
    color = g.mix(inner, (0.015, 0.015, 0.016), color)                    # the dark frame (and the plate's edges)
    relief = g.bump(g.add(ink, inner), 0.35, 0.0015)                       # embossed characters and rim
    return g.principled(base_color=color, roughness=roughness, normal=relief)
