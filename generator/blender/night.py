"""Night: dark sky, a faint moon, street-lamp and headlight spot lights.

Light objects are created once per scene in one collection and shown only at night;
emissive surfaces (lamp glass, lit windows, vehicle and signal lamps) are switched by
the scene controls (:mod:`generator.blender.controls`).
"""

from __future__ import annotations

import math

import numpy as np

from generator.geometry import apply
from generator.blender.bpy_guard import bpy, mathutils
from generator.blender.lighting import ensure_lamp
from generator.blender.nodes import Nodes
from generator.world.scene import SceneModel

LAMP_POWER_W = 900.0
LAMP_CONE_DEG = 130.0
LAMP_COLOR = (1.0, 0.78, 0.5)      # warm high-pressure sodium / 3000 K LED
HEADLIGHT_POWER_W = 250.0
HEADLIGHT_CONE_DEG = 40.0
HEADLIGHT_COLOR = (1.0, 0.95, 0.85)
NIGHT_SKY = (0.004, 0.006, 0.012)
MOON_STRENGTH = 0.015


def _spot(name: str, power: float, cone_deg: float, color, location, direction, collection) -> bpy.types.Object:
    data = bpy.data.lights.new(name, "SPOT")
    data.energy = power
    data.spot_size = math.radians(cone_deg)
    data.spot_blend = 0.6
    data.color = color
    data.shadow_soft_size = 0.15
    data["ug_energy"] = power
    ob = bpy.data.objects.new(name, data)
    ob.location = tuple(float(v) for v in location)
    ob.rotation_euler = mathutils.Vector(tuple(float(v) for v in direction)).to_track_quat("-Z", "Y").to_euler()
    collection.objects.link(ob)
    return ob


def headlight(name: str, location, direction, collection) -> bpy.types.Object:
    """One headlight spot at ``location`` shining along ``direction`` (dark until :func:`set_night`)."""
    ob = _spot(name, HEADLIGHT_POWER_W, HEADLIGHT_CONE_DEG, HEADLIGHT_COLOR, location, direction, collection)
    ob.data.energy = 0.0
    return ob


def build_lights(model: SceneModel, parent: "bpy.types.Collection") -> tuple["bpy.types.Collection", dict]:
    """Create the night light objects of ``model``; return their collection and counts per group."""
    coll = bpy.data.collections.new("urbangen_night_lights")
    parent.children.link(coll)
    counts = {"street_lamps": 0, "headlights": 0}
    for o in model.objects:
        anchors = model.prototypes[o.prototype].anchors
        if "lamp" in anchors:
            for p in apply(o.transform, anchors["lamp"]):
                _spot(f"{o.name}_lamp", LAMP_POWER_W, LAMP_CONE_DEG, LAMP_COLOR, p, (0, 0, -1), coll)
                counts["street_lamps"] += 1
        if "headlight" in anchors and o.attrs.get("placement") != "parked":
            fwd = o.transform[:3, :3] @ np.array([1.0, 0.0, -0.12])
            for p in apply(o.transform, anchors["headlight"]):
                _spot(f"{o.name}_headlight", HEADLIGHT_POWER_W, HEADLIGHT_CONE_DEG, HEADLIGHT_COLOR, p, fwd, coll)
                counts["headlights"] += 1
    set_night(None, coll, False)
    return coll, counts


def ensure_moon(scene: "bpy.types.Scene") -> "bpy.types.Object":
    """The moon lamp, created once and dark (see :func:`generator.blender.lighting.ensure_lamp`)."""
    return ensure_lamp(scene, "urbangen_moon")


def night_world(scene: "bpy.types.Scene") -> dict:
    """A dark blue night sky and a faint moon; return the lighting parameters."""
    world = bpy.data.worlds.get("urbangen_night") or bpy.data.worlds.new("urbangen_night")
    g = Nodes(world.node_tree)
    bg = g.node("ShaderNodeBackground")
    g.set(bg.inputs["Color"], NIGHT_SKY)
    g.set(bg.inputs["Strength"], 1.0)
    g.output(bg.outputs[0], "ShaderNodeOutputWorld")
    scene.world = world
    moon = ensure_moon(scene)
    moon.rotation_euler = (math.radians(50), 0.0, math.radians(30))
    moon.data.color = (0.7, 0.8, 1.0)
    moon.data.angle = math.radians(0.5)
    return {"sky_model": "night_constant", "sky_color": list(NIGHT_SKY), "moon_strength_w_m2": MOON_STRENGTH,
            "street_lamp_power_w": LAMP_POWER_W, "headlight_power_w": HEADLIGHT_POWER_W}


def set_night(scene, lights: "bpy.types.Collection", night: bool) -> None:
    """Switch the night lights and the moon on at night and the sun on by day.

    Lights are never hidden or unhidden, only dimmed to zero: with persistent data, adding or
    removing lights reorders Cycles' light list in a run-dependent way and changes the noise
    of every later render. Zero-strength lights are skipped by Cycles without reordering.
    """
    for ob in lights.objects:
        ob.data.energy = ob.data["ug_energy"] if night else 0.0
    moon = bpy.data.objects.get("urbangen_moon")
    if moon is not None:
        moon.data.energy = MOON_STRENGTH if night else 0.0
    sun = bpy.data.objects.get("urbangen_sun")
    if sun is not None and night:
        sun.data.energy = 0.0
