"""Sunlight: a Sun lamp whose strength and colour follow the sun's path through the air.

The sun direction uses a compass azimuth (0 deg = north = +y, 90 deg = east = +x) and an
elevation above the horizon. The sky (:mod:`generator.blender.sky`) has no sun disc; a Sun
lamp of the same direction casts the (sharp) shadows, so shadows are consistent with the sky.

The lamp's irradiance follows the air mass (Kasten & Young 1989) with a broadband extinction
per channel (Rayleigh plus a clear-day aerosol load), normalised to :data:`SUN_STRENGTH` at
:data:`REFERENCE_ELEVATION_DEG`: a low morning or evening sun is dimmer and redder, at dusk it
is a faint orange light and below the horizon it is off (twilight: only the sky lights the
town). Overcast skies dim it to :data:`OVERCAST_SUN` and widen it to :data:`OVERCAST_SUN_ANGLE_DEG`,
so shadows are faint and soft.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from generator.blender import sky
from generator.blender.bpy_guard import bpy, mathutils
from generator.weather import (
    OVERCAST_SHARE,
    OVERCAST_SUN,
    REFERENCE_ELEVATION_DEG,
    SUN_STRENGTH,
    UNITS_PER_LUX,
    global_irradiance,
)

__all__ = ["UNITS_PER_LUX", "SUN_STRENGTH", "day_world", "ensure_lamp", "ensure_sun", "sun_direction"]

SUN_ANGLE_DEG = 0.53
#: Broadband optical depth at the zenith per channel (R, G, B): Rayleigh plus clear-day aerosols.
EXTINCTION = (0.13, 0.21, 0.36)
#: Overcast: the sun's (wide) angle; its strength is OVERCAST_SUN of the clear sky's.
OVERCAST_SUN_ANGLE_DEG = 30.0


@dataclass(frozen=True)
class DayLight:
    """Sun position in degrees and the sky over it."""

    sun_elevation_deg: float
    sun_azimuth_deg: float
    cloud_cover: float = 0.0
    cloud_seed: float = 0.0
    overcast: bool = False


def sun_direction(elevation_deg: float, azimuth_deg: float) -> np.ndarray:
    """(3,) unit vector pointing from the ground toward the sun, world frame."""
    el, az = math.radians(elevation_deg), math.radians(azimuth_deg)
    return np.array([math.sin(az) * math.cos(el), math.cos(az) * math.cos(el), math.sin(el)])


def air_mass(elevation_deg: float) -> float:
    """Relative optical air mass at a sun elevation (Kasten & Young 1989); inf below -2 deg."""
    h = float(elevation_deg)
    if h < -2.0:
        return math.inf
    return 1.0 / (math.sin(math.radians(max(h, 0.0))) + 0.50572 * (h + 6.07995) ** -1.6364)


def sun_irradiance(elevation_deg: float) -> np.ndarray:
    """(3,) float: the sun lamp's irradiance per channel (render units, on a surface facing the sun).

    0 once the sun is below the horizon.
    """
    if elevation_deg <= 0.0:
        return np.zeros(3)
    tau = np.asarray(EXTINCTION)
    return SUN_STRENGTH * np.exp(-tau * (air_mass(elevation_deg) - air_mass(REFERENCE_ELEVATION_DEG)))


def ensure_lamp(scene: bpy.types.Scene, name: str) -> bpy.types.Object:
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


def ensure_sun(scene: bpy.types.Scene) -> bpy.types.Object:
    """The sun lamp (see :func:`ensure_lamp`)."""
    return ensure_lamp(scene, "urbangen_sun")


def day_world(scene: bpy.types.Scene, light: DayLight) -> dict:
    """Set the sky (clouds or overcast) and the sun lamp of a day or dusk image; return the metadata."""
    el = light.sun_elevation_deg
    e_sun = sun_irradiance(el)
    share = OVERCAST_SUN if light.overcast else 1.0
    e_lamp = e_sun * share
    overcast_e = OVERCAST_SHARE * global_irradiance(el)
    info = sky.daylight_world(scene, sun_elevation_deg=el, sun_azimuth_deg=light.sun_azimuth_deg,
                              sun_rgb=tuple(float(c) for c in e_sun), cloud_cover=light.cloud_cover,
                              cloud_seed=light.cloud_seed, overcast=light.overcast, overcast_irradiance=overcast_e)
    sun = ensure_sun(scene)
    d = sun_direction(el, light.sun_azimuth_deg)
    # A sun lamp shines along its local -z: align -z with -d.
    sun.rotation_euler = mathutils.Vector((-d).tolist()).to_track_quat("-Z", "Y").to_euler()
    strength = float(e_lamp.max())
    sun.data.energy = strength
    sun.data.color = tuple(float(c) for c in (e_lamp / strength if strength > 0 else np.ones(3)))
    angle = OVERCAST_SUN_ANGLE_DEG if light.overcast else SUN_ANGLE_DEG
    sun.data.angle = math.radians(angle)
    info.update({
        "sun_direction_world": [float(v) for v in d],
        "sun_strength_w_m2": strength,
        "sun_irradiance_rgb": [float(c) for c in e_lamp],
        "sun_angle_deg": angle,
        "air_mass": air_mass(el),
        "global_irradiance_clear": global_irradiance(el),
    })
    return info
