"""Material recipes of vehicles and people, whose colours come per object.

Prototype meshes are shared by many objects, so a car's paint and a person's garments, skin and
hair are object properties (:mod:`generator.layout.placement.appearance` draws them; the layout stores them
in ``attrs``; :func:`generator.blender.geometry.new_object` writes them): ``Object.color`` holds
the paint or the top, ``ug_<name>_color`` the others, ``ug_paint_metallic`` 0/1 and ``ug_outfit``
1 where a person's colours were given (0: the earlier look, tones from the object's random
number, so scenes without drawn outfits still render sensibly); a vehicle's paint finish
(``ug_paint_matte``, ``ug_paint_dirt``) comes from :mod:`generator.blender.vehicle_finish`. Same
signature as :mod:`generator.blender.recipes`.
"""

from __future__ import annotations

from generator.blender.car_seam_shader import grille_slats, seam_gaps
from generator.blender.nodes import Nodes
from generator.blender.plate_shader import plate_surface
from generator.labels import class_table
from generator.materials import material_table


def _per_object(g: Nodes, name: str, fallback):
    """The object's ``ug_<name>_color`` where ``ug_outfit`` is 1, else ``fallback`` (a colour or socket)."""
    return g.mix(g.attr("ug_outfit", "OBJECT", "Fac"), fallback, g.attr(f"ug_{name}_color", "OBJECT", "Color"))


def _height(g: Nodes):
    """The shading point's height in the object's frame (a vehicle's origin is on the ground), metres."""
    sep = g.node("ShaderNodeSeparateXYZ")
    g.set(sep.inputs[0], g.coords("Object"))
    return sep.outputs["Z"]


def car_paint(g: Nodes, rng, seams: bool = False):
    """Vehicle paint of one of three finishes, with road grime toward the sills.

    Object properties (:mod:`generator.blender.vehicle_finish`): ``ug_paint_metallic`` (metallic paints of
    the palette: flakes under the clear coat), ``ug_paint_matte`` (satin, no clear coat) and
    ``ug_paint_dirt`` (0 clean .. 1 filthy: grime rising from the sills in streaks, dust over all).
    With ``seams`` (the body shell) the panel gaps and door handles of :mod:`generator.blender.car_seam_shader`.
    """
    metallic = g.attr("ug_paint_metallic", "OBJECT", "Fac")
    matte = g.attr("ug_paint_matte", "OBJECT", "Fac")
    dirt = g.attr("ug_paint_dirt", "OBJECT", "Fac")
    co = g.coords("Object")
    # metallic flakes: sub-millimetre cells tilting the base layer's normal under a smooth coat
    flakes = g.voronoi(co, scale=900.0, out="Distance")
    normal = g.bump(g.mul(flakes, metallic), 0.25, 0.0004)
    rough = g.lerp(matte, g.lerp(metallic, 0.28, 0.36), 0.62)
    coat = g.lerp(matte, 1.0, 0.0)
    # grime: up to ~0.25 m on a clean car, to the belt line on a filthy one, streaked vertically
    reach = g.add(0.12, g.mul(dirt, 0.75))
    low = g.math("SUBTRACT", 1.0, g.smooth(g.math("DIVIDE", _height(g), reach), 0.35, 1.0))
    streaks = g.noise(g.mapping(co, scale=(6.0, 6.0, 1.5)), scale=3.0, detail=3.0)
    grime = g.math("MINIMUM", 1.0, g.mul(g.mul(dirt, low), g.add(0.55, g.mul(streaks, 0.7))))
    dust = g.mul(dirt, g.add(0.12, g.mul(g.noise(co, scale=2.0, detail=2.0), 0.18)))
    base = g.mix(dust, g.object_info("Color"), (0.30, 0.27, 0.23))
    base = g.mix(grime, base, (0.11, 0.09, 0.065))
    rough = g.lerp(g.math("MAXIMUM", grime, dust), rough, 0.9)
    coat = g.lerp(grime, coat, 0.05)
    if seams:                                   # panel gaps: dark, matte grooves; handles in a shadowed recess
        gap, handle = seam_gaps(g)
        base = g.mix(g.math("MAXIMUM", gap, g.mul(handle, 0.8)), base, (0.012, 0.012, 0.012))
        rough, coat = g.lerp(gap, rough, 0.7), g.lerp(gap, coat, 0.0)
        normal = g.bump(g.math("SUBTRACT", 1.0, gap), 0.6, 0.002, normal=normal)
    return g.principled(base_color=base, metallic=g.lerp(grime, g.lerp(metallic, 0.0, 0.7), 0.0), roughness=rough,
                        coat=coat, coat_roughness=0.04, normal=normal)


def car_body(g: Nodes, rng):
    """The curved shell of a car: the same paint, shaded smooth (``car_paint`` stays flat for boxy parts), with
    its panel gaps and door handles."""
    return car_paint(g, rng, seams=True)


def _see_through(g: Nodes):
    """1 on the faces of the classes whose cabin is modelled (``interiors`` in materials.yaml), else 0."""
    classes = class_table()
    out = 0.0
    for name in material_table().interiors:
        eq = g.node("ShaderNodeMath", operation="COMPARE")
        g.set(eq.inputs[0], g.attr("class_id"))
        eq.inputs[1].default_value, eq.inputs[2].default_value = float(classes.id(name)), 0.25
        out = g.add(out, eq.outputs[0])
    return g.math("MINIMUM", out, 1.0)


def car_glass(g: Nodes, rng):
    """Vehicle and shelter glass. On a car (a modelled cabin behind it) thin tinted glass the camera sees
    through, reflecting by Fresnel; elsewhere (trucks, buses, shelters: nothing behind it) dark and glossy."""
    opaque = g.principled(base_color=(0.01, 0.012, 0.015), roughness=0.02, ior=1.5, specular=1.0)
    tint = g.node("ShaderNodeBsdfTransparent")
    g.set(tint.inputs["Color"], (0.5, 0.56, 0.55))
    gloss = g.node("ShaderNodeBsdfGlossy")
    g.set(gloss.inputs["Color"], (1.0, 1.0, 1.0))
    g.set(gloss.inputs["Roughness"], 0.03)
    fres = g.node("ShaderNodeFresnel")
    g.set(fres.inputs["IOR"], 1.52)
    thin = g.mix_shader(fres.outputs[0], tint.outputs[0], gloss.outputs[0])
    return g.mix_shader(_see_through(g), opaque, thin)


def car_interior(g: Nodes, rng):
    """Seats, dashboard, door cards and floor: black, grey or beige per car, a fabric grain."""
    tone = g.ramp(g.object_info("Random"), [(0.0, (0.012, 0.012, 0.013)), (0.6, (0.035, 0.034, 0.033)),
                                            (0.9, (0.16, 0.13, 0.095))])
    grain = g.bump(g.noise(g.coords("Object"), scale=180.0, detail=2.0), 0.15, 0.002)
    return g.principled(base_color=tone, roughness=0.8, normal=grain)


def car_headliner(g: Nodes, rng):
    return g.principled(base_color=(0.32, 0.31, 0.29), roughness=0.95)


def car_trim(g: Nodes, rng):
    """Black plastic: sills, pillars, the grille (horizontal slats with dark gaps, on car bodies with seams)."""
    grille, slat = grille_slats(g)
    gap = g.mul(grille, g.math("SUBTRACT", 1.0, slat))
    base = g.mix(gap, (0.018, 0.018, 0.02), (0.002, 0.002, 0.002))
    rough = g.lerp(grille, 0.55, g.lerp(slat, 0.9, 0.35))
    return g.principled(base_color=base, roughness=rough, normal=g.bump(g.mul(grille, slat), 0.5, 0.004))


def wheel_rim(g: Nodes, rng):
    return g.principled(base_color=(0.5, 0.51, 0.53), metallic=0.9, roughness=0.3)


def licence_plate(g: Nodes, rng):
    """White plates; about one car in eight yellow (Dutch plates, British rear plates); a frame, the EU band
    and the car's own registration (:mod:`generator.blender.plate_shader`)."""
    yellow = g.math("GREATER_THAN", g.object_info("Random"), 0.88)
    return plate_surface(g, g.mix(yellow, (0.78, 0.78, 0.72), (0.8, 0.6, 0.04)))


def _folds(g: Nodes):
    """Soft creases of cloth (a bump of low-frequency noise in the person's frame, a few cm across)."""
    return g.bump(g.noise(g.coords("Object"), scale=22.0, detail=1.0), strength=0.3, distance=0.006)


def clothing(g: Nodes, rng):
    """The top (and the sleeves): ``Object.color``."""
    return g.principled(base_color=g.object_info("Color"), roughness=0.85, sheen=0.3, normal=_folds(g))


def clothing_bottom(g: Nodes, rng):
    fallback = g.mix(0.5, g.object_info("Color"), (0.03, 0.04, 0.07))
    return g.principled(base_color=_per_object(g, "bottom", fallback), roughness=0.8, sheen=0.2, normal=_folds(g))


def shoes(g: Nodes, rng):
    return g.principled(base_color=_per_object(g, "shoe", (0.015, 0.015, 0.015)), roughness=0.5)


def skin(g: Nodes, rng):
    fallback = g.mix(g.object_info("Random"), (0.45, 0.28, 0.2), (0.12, 0.07, 0.045))
    return g.principled(base_color=_per_object(g, "skin", fallback), roughness=0.5, subsurface=0.1)


def hair(g: Nodes, rng):
    """Hair colour over strands: noise stretched 12x along the person's height, darkening and bumping (no sheen:
    it greys dark hair under a bright sky)."""
    fallback = g.mix(g.object_info("Random"), (0.02, 0.015, 0.01), (0.25, 0.17, 0.08))
    strands = g.noise(g.mapping(g.coords("Object"), scale=(1.0, 1.0, 0.08)), scale=240.0, detail=2.0)
    tone = g.mix(g.smooth(strands, 0.3, 0.7), g.hsv(_per_object(g, "hair", fallback), value=0.6),
                 _per_object(g, "hair", fallback))
    return g.principled(base_color=tone, roughness=0.6, normal=g.bump(strands, 0.35, 0.002))
