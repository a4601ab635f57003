"""World and lights: a physical sky with a matching sun by day.

The sun direction uses a compass azimuth (0 deg = north = +y, 90 deg = east = +x) and
an elevation above the horizon. The sky is Blender's multiple-scattering sky model
without its sun disc; a Sun lamp of the same direction casts the (sharp) shadows, so
shadows are consistent with the sky.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from generator.blender.bpy_guard import bpy, mathutils
from generator.blender.nodes import Nodes

SUN_ANGLE_DEG = 0.53
#: Radiometric scale of the sky and sun, chosen so a sunlit grey surface lands near 0.5 (linear).
SKY_STRENGTH = 0.12
SUN_STRENGTH = 3.2


@dataclass(frozen=True)
class DayLight:
    """Sun position in degrees."""

    sun_elevation_deg: float
    sun_azimuth_deg: float


def sun_direction(elevation_deg: float, azimuth_deg: float) -> np.ndarray:
    """(3,) unit vector pointing from the ground toward the sun, world frame."""
    el, az = math.radians(elevation_deg), math.radians(azimuth_deg)
    return np.array([math.sin(az) * math.cos(el), math.cos(az) * math.cos(el), math.sin(el)])


def ensure_lamp(scene: "bpy.types.Scene", name: str) -> "bpy.types.Object":
    """A directional lamp ``name`` (created once, switched off).

    Every Renderer creates its sun and moon up front and only changes their strength, so the
    scene's light list -- and therefore Cycles' sampling -- never depends on earlier renders.
    """
    lamp = bpy.data.objects.get(name)
    if lamp is None:
        lamp = bpy.data.objects.new(name, bpy.data.lights.new(name, "SUN"))
        scene.collection.objects.link(lamp)
        lamp.data.energy = 0.0
    return lamp


def ensure_sun(scene: "bpy.types.Scene") -> "bpy.types.Object":
    """The sun lamp (see :func:`ensure_lamp`)."""
    return ensure_lamp(scene, "urbangen_sun")


def day_world(scene: "bpy.types.Scene", light: DayLight) -> dict:
    """Set a physical sky and a sun lamp; return the lighting parameters for metadata."""
    world = bpy.data.worlds.get("urbangen_sky") or bpy.data.worlds.new("urbangen_sky")
    g = Nodes(world.node_tree)
    sky = g.node("ShaderNodeTexSky", sky_type="MULTIPLE_SCATTERING")
    sky.sun_disc = False
    sky.sun_elevation = math.radians(light.sun_elevation_deg)
    # Blender's sky "sun rotation" is a compass bearing like ours (0 = +y, clockwise seen from above):
    # checked by aiming a camera at the lamp's direction and finding the sky's sun disc at the centre.
    sky.sun_rotation = math.radians(light.sun_azimuth_deg)
    sky.altitude = 0.0
    sky.air_density = 1.0
    sky.aerosol_density = 1.0
    bg = g.node("ShaderNodeBackground")
    g.set(bg.inputs["Color"], sky.outputs["Color"])
    g.set(bg.inputs["Strength"], SKY_STRENGTH)
    g.output(bg.outputs[0], "ShaderNodeOutputWorld")
    scene.world = world

    sun = ensure_sun(scene)
    d = sun_direction(light.sun_elevation_deg, light.sun_azimuth_deg)
    # A sun lamp shines along its local -z: align -z with -d.
    sun.rotation_euler = mathutils.Vector((-d).tolist()).to_track_quat("-Z", "Y").to_euler()
    sun.data.energy = SUN_STRENGTH
    sun.data.angle = math.radians(SUN_ANGLE_DEG)
    low = max(0.0, min(1.0, (20.0 - light.sun_elevation_deg) / 20.0))
    sun.data.color = (1.0, 1.0 - 0.15 * low, 1.0 - 0.35 * low)
    return {
        "sky_model": "blender_multiple_scattering",
        "sun_elevation_deg": light.sun_elevation_deg,
        "sun_azimuth_deg": light.sun_azimuth_deg,
        "sun_direction_world": [float(v) for v in d],
        "sky_strength": SKY_STRENGTH,
        "sun_strength_w_m2": SUN_STRENGTH,
        "sun_angle_deg": SUN_ANGLE_DEG,
    }
