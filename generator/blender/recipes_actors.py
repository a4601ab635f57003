"""Material recipes of vehicles and people, whose colours come per object.

Prototype meshes are shared by many objects, so a car's paint and a person's garments, skin and
hair are object properties (:mod:`generator.layout.placement.appearance` draws them; the layout stores them
in ``attrs``; :func:`generator.blender.geometry.new_object` writes them): ``Object.color`` holds
the paint or the top, ``ug_<name>_color`` the others, ``ug_paint_metallic`` 0/1 and ``ug_outfit``
1 where a person's colours were given (0: the earlier look, tones from the object's random
number, so scenes without drawn outfits still render sensibly). Same signature as
:mod:`generator.blender.recipes`.
"""

from __future__ import annotations

from generator.blender.nodes import Nodes


def _per_object(g: Nodes, name: str, fallback):
    """The object's ``ug_<name>_color`` where ``ug_outfit`` is 1, else ``fallback`` (a colour or socket)."""
    return g.mix(g.attr("ug_outfit", "OBJECT", "Fac"), fallback, g.attr(f"ug_{name}_color", "OBJECT", "Color"))


def car_paint(g: Nodes, rng):
    metallic = g.attr("ug_paint_metallic", "OBJECT", "Fac")
    return g.principled(base_color=g.object_info("Color"), metallic=g.lerp(metallic, 0.0, 0.7),
                        roughness=g.lerp(metallic, 0.28, 0.38), coat=1.0, coat_roughness=0.04)


def car_body(g: Nodes, rng):
    """The curved shell of a car: the same paint, shaded smooth (``car_paint`` stays flat for boxy parts)."""
    return car_paint(g, rng)


def car_trim(g: Nodes, rng):
    return g.principled(base_color=(0.018, 0.018, 0.02), roughness=0.55)


def wheel_rim(g: Nodes, rng):
    return g.principled(base_color=(0.5, 0.51, 0.53), metallic=0.9, roughness=0.3)


def licence_plate(g: Nodes, rng):
    return g.principled(base_color=(0.78, 0.78, 0.72), roughness=0.35)


def clothing(g: Nodes, rng):
    """The top (and the sleeves): ``Object.color``."""
    return g.principled(base_color=g.object_info("Color"), roughness=0.85, sheen=0.3)


def clothing_bottom(g: Nodes, rng):
    fallback = g.mix(0.5, g.object_info("Color"), (0.03, 0.04, 0.07))
    return g.principled(base_color=_per_object(g, "bottom", fallback), roughness=0.8, sheen=0.2)


def shoes(g: Nodes, rng):
    return g.principled(base_color=_per_object(g, "shoe", (0.015, 0.015, 0.015)), roughness=0.5)


def skin(g: Nodes, rng):
    fallback = g.mix(g.object_info("Random"), (0.45, 0.28, 0.2), (0.12, 0.07, 0.045))
    return g.principled(base_color=_per_object(g, "skin", fallback), roughness=0.5, subsurface=0.1)


def hair(g: Nodes, rng):
    fallback = g.mix(g.object_info("Random"), (0.02, 0.015, 0.01), (0.25, 0.17, 0.08))
    return g.principled(base_color=_per_object(g, "hair", fallback), roughness=0.6)
