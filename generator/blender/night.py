"""Night: a dark city sky, a faint moon, street-lamp and headlight spot lights -- at real ratios.

Night is as dim as a real one, in the units of the day renders (:data:`UNITS_PER_LUX`: the
clear day's sun stands for ~100 klx): the street lamps are the main light (a 4000 cd luminaire
peak, ~60 lx on the road under a lamp, EN 13201 street lighting), headlights 20 000 cd low
beams, the moon 0.1 lx (a gibbous moon) and the sky the orange-grey glow of a city (zenith
~0.02 cd/m^2, brighter at the horizon; an overcast deck reflects ~10x more and hides the moon).
A night image's log-average radiance is therefore some 10-12 EV below a clear day's, as
measured on real streets; the camera model's exposure (:mod:`generator.postfx.camera`) brings it
up as far as a real camera's exposure time and gain reach.

Light objects are created once per scene in one collection and switched on at dusk and night;
emissive surfaces (lamp glass, lit windows, vehicle and signal lamps) are scaled by the
scene controls (:mod:`generator.blender.controls`, :data:`EMISSION_SCALE`).
"""

from __future__ import annotations

import json
import math

import numpy as np

from generator.blender.bpy_guard import bpy, mathutils
from generator.blender.geometry import lights_on
from generator.blender.lighting import UNITS_PER_LUX, ensure_lamp
from generator.blender.nodes import Nodes
from generator.blender.sky import keep_world, kept_world
from generator.geometry import apply
from generator.world.scene import SceneModel

#: Spot "power" in Blender is that of a point light of the same intensity: I = P / (4 pi) W/sr;
#: cd x UNITS_PER_LUX = W/sr in render units.
LAMP_CANDELA = 4000.0
LAMP_POWER_W = 4.0 * math.pi * LAMP_CANDELA * UNITS_PER_LUX
LAMP_CONE_DEG = 130.0
LAMP_COLOR = (1.0, 0.78, 0.5)      # warm high-pressure sodium / 3000 K LED
HEADLIGHT_CANDELA = 20_000.0
HEADLIGHT_POWER_W = 4.0 * math.pi * HEADLIGHT_CANDELA * UNITS_PER_LUX
HEADLIGHT_CONE_DEG = 40.0
HEADLIGHT_COLOR = (1.0, 0.95, 0.85)
#: City sky glow, cd/m^2: zenith and horizon of a clear night, and an overcast deck lit from below.
SKY_ZENITH_CD = 0.02
SKY_HORIZON_CD = 0.12
SKY_OVERCAST_CD = 0.3
NIGHT_SKY_TINT = (0.75, 0.8, 1.0)
GLOW_TINT = (1.0, 0.72, 0.45)
#: Moonlight, lux (a gibbous moon; full moon ~0.25 lx), and its colour.
MOON_LUX = 0.1
MOON_STRENGTH = MOON_LUX * UNITS_PER_LUX
#: The emissive surfaces' strengths at dusk and night (x the recipes' strengths, which are a day's
#: scale): lamp glass ~30 000 cd/m^2, headlight lenses ~25 000 cd/m^2 and tail lights ~10 000 cd/m^2
#: (both on one switch), lit windows 20..600 cd/m^2 (per pane, :mod:`generator.blender.recipes`),
#: signals ~10 000 cd/m^2.
EMISSION_SCALE = {"street_lamps": 0.016, "vehicle_lights": 0.02, "windows": 3.0e-4, "traffic_lights": 0.01}


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


def build_lights(model: SceneModel, parent: bpy.types.Collection) -> tuple[bpy.types.Collection, dict]:
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
        if "headlight" in anchors and lights_on(o.attrs):
            fwd = o.transform[:3, :3] @ np.array([1.0, 0.0, -0.12])
            for p in apply(o.transform, anchors["headlight"]):
                _spot(f"{o.name}_headlight", HEADLIGHT_POWER_W, HEADLIGHT_CONE_DEG, HEADLIGHT_COLOR, p, fwd, coll)
                counts["headlights"] += 1
    set_night(None, coll, False)
    return coll, counts


def ensure_moon(scene: bpy.types.Scene) -> bpy.types.Object:
    """The moon lamp, created once and dark (see :func:`generator.blender.lighting.ensure_lamp`)."""
    return ensure_lamp(scene, "urbangen_moon")


def night_world(scene: bpy.types.Scene, overcast: bool = False, cloud_seed: float = 0.0) -> dict:
    """The night sky (city glow; an orange-grey deck when overcast) and the moon; return the parameters.

    The world is kept when it is already the scene's and was built with the same arguments
    (:func:`generator.blender.sky.kept_world`); the moon is set every time."""
    params = json.dumps([bool(overcast), float(cloud_seed)])
    info = kept_world(scene, "urbangen_night", params) or _build_night_world(scene, overcast, cloud_seed, params)
    moon = ensure_moon(scene)
    moon.rotation_euler = (math.radians(50), 0.0, math.radians(30))
    moon.data.color = (0.7, 0.8, 1.0)
    moon.data.angle = math.radians(0.5)
    moon.data.energy = 0.0 if overcast else MOON_STRENGTH
    return info


def _build_night_world(scene: bpy.types.Scene, overcast: bool, cloud_seed: float, params: str) -> dict:
    """Build the night world's node tree, make it the scene's and return its parameters."""
    world = bpy.data.worlds.get("urbangen_night") or bpy.data.worlds.new("urbangen_night")
    g = Nodes(world.node_tree)
    z = g.node("ShaderNodeSeparateXYZ")
    g.set(z.inputs[0], g.coords("Generated"))
    up = g.math("MAXIMUM", z.outputs["Z"], 0.0)
    if overcast:
        zen = tuple(SKY_OVERCAST_CD * UNITS_PER_LUX * c for c in GLOW_TINT)
        hor = tuple(1.3 * v for v in zen)
        deck = g.noise(scale=3.0, detail=4, w=cloud_seed)
        color = g.mix(1.0, g.mix(g.smooth(up, 0.0, 0.5), hor, zen), g.mix(deck, (0.8,) * 3, (1.2,) * 3), "MULTIPLY")
    else:
        zen = tuple(SKY_ZENITH_CD * UNITS_PER_LUX * c for c in NIGHT_SKY_TINT)
        hor = tuple(SKY_HORIZON_CD * UNITS_PER_LUX * c for c in GLOW_TINT)
        color = g.mix(g.smooth(up, 0.0, 0.35), hor, zen)
    bg = g.node("ShaderNodeBackground")
    g.set(bg.inputs["Color"], color)
    g.set(bg.inputs["Strength"], 1.0)
    g.output(bg.outputs[0], "ShaderNodeOutputWorld")
    scene.world = world
    return keep_world(world, params, {
        "sky_model": "night_city_glow_overcast" if overcast else "night_city_glow", "overcast": overcast,
        "sky_zenith_radiance": [float(v) for v in zen], "sky_horizon_radiance": [float(v) for v in hor],
        "moon_strength_w_m2": 0.0 if overcast else MOON_STRENGTH})


def lights_record() -> dict:
    """The artificial lights' parameters for an image's metadata (dusk and night)."""
    return {"street_lamp_power_w": LAMP_POWER_W, "street_lamp_candela": LAMP_CANDELA,
            "headlight_power_w": HEADLIGHT_POWER_W, "headlight_candela": HEADLIGHT_CANDELA,
            "emission_scale": dict(EMISSION_SCALE)}


def set_night(scene, lights: bpy.types.Collection, lit: bool) -> None:
    """Switch the street lamps and headlights on (dusk and night) or off, and the moon off.

    The moon is switched on by :func:`night_world`; the sun is set by
    :func:`generator.blender.lighting.day_world` (day and dusk) and switched off here at night.
    Lights are never hidden or unhidden, only dimmed to zero: with persistent data, adding or
    removing lights reorders Cycles' light list in a run-dependent way and changes the noise
    of every later render. Zero-strength lights are skipped by Cycles without reordering.
    """
    for ob in lights.objects:
        ob.data.energy = ob.data["ug_energy"] if lit else 0.0
    moon = bpy.data.objects.get("urbangen_moon")
    if moon is not None:
        moon.data.energy = 0.0
    sun = bpy.data.objects.get("urbangen_sun")
    if sun is not None:
        sun.data.energy = 0.0
