"""The daylight sky: Blender's physical sky with procedural clouds, or an overcast deck.

One world node tree serves day and dusk (:func:`daylight_world`):

* **clear** (``overcast`` false): Blender's multiple-scattering sky (no sun disc: the Sun lamp
  of :mod:`generator.blender.lighting` is the sun) under broken clouds. The clouds are a 4D
  noise on the plane of the cloud base, seen through the view direction (``xy / z``), so they
  shrink and crowd toward the horizon as real cumulus do; ``cloud_cover`` sets the threshold
  (0: none, 0.6: most of the sky), ``cloud_seed`` the pattern. A cloud's underside is grey
  sky light (the sky's zenith colour) and its sunlit flanks are lit by the sun's colour and
  strength, so low suns give orange clouds. The sun keeps a gap of clear sky around it, so the
  sky never shows a cloud over a sun that casts full shadows.
* **overcast**: one grey deck with the CIE standard overcast sky's gradation,
  ``L(h) = L_z (1 + 2 sin h) / 3``, a faint cloud texture, and a horizontal illuminance of
  :data:`generator.weather.OVERCAST_SHARE` of the clear sky's; the sun lamp is dimmed and widened by the caller.

Radiance units are those of the renders: a clear day's sunlit grey surface is about 0.5.
"""

from __future__ import annotations

import json
import math

from generator.blender.bpy_guard import bpy
from generator.blender.nodes import Nodes

#: Radiometric scale of Blender's sky texture (a sunlit grey surface lands near 0.5, linear).
SKY_STRENGTH = 0.12
#: Overcast deck colour (a touch blue: the cloud base is lit by scattered sky light).
OVERCAST_TINT = (0.93, 0.96, 1.0)
#: Cloud albedo seen from below on the sunlit side, and the floor of the grey underside (x zenith sky).
CLOUD_LIT = 0.55
CLOUD_SHADE = 1.6
#: Clear gap around the sun, degrees: clouds fade out between these angles from it.
SUN_GAP_DEG = (6.0, 14.0)
#: Cloud-base plane: noise scale per unit of ``xy / z`` (features of about a cloud-base height).
CLOUD_SCALE = 0.3


def _split(g: Nodes, vec):
    n = g.node("ShaderNodeSeparateXYZ")
    g.set(n.inputs[0], vec)
    return n.outputs["X"], n.outputs["Y"], n.outputs["Z"]


def _join(g: Nodes, x, y, z):
    n = g.node("ShaderNodeCombineXYZ")
    for s, v in zip(n.inputs, (x, y, z), strict=False):
        g.set(s, v)
    return n.outputs[0]


def _vmath(g: Nodes, op: str, a, b=(0.0, 0.0, 0.0), out: int = 0):
    n = g.node("ShaderNodeVectorMath", operation=op)
    g.set(n.inputs[0], a)
    g.set(n.inputs[1], b)
    return n.outputs[out]


def _scale_rgb(g: Nodes, color, factor):
    """``color * factor`` (factor a float socket or number), as a colour."""
    return g.mix(1.0, color, (factor,) * 3 if isinstance(factor, (int, float)) else _join(g, factor, factor, factor),
                 "MULTIPLY")


def overcast_zenith(horizontal_irradiance: float) -> float:
    """Zenith radiance of a CIE overcast sky giving ``horizontal_irradiance`` on the ground.

    The CIE overcast sky ``L(h) = L_z (1 + 2 sin h) / 3`` integrates to ``E = 7 pi L_z / 9``.
    """
    return 9.0 * horizontal_irradiance / (7.0 * math.pi)


def kept_world(scene: bpy.types.Scene, name: str, params: str) -> dict | None:
    """The metadata of world ``name`` when it is the scene's world and was built from ``params``, else None.

    Rebuilding a world's node tree costs Cycles 1.3-2.5 s at the next render (its shaders, the sky
    textures' precomputation, the importance map) even when nothing changed; a world asked for again
    with the same parameters is kept as it is.
    """
    world = bpy.data.worlds.get(name)
    if world is None or scene.world != world or world.get("ug_params") != params:
        return None
    return json.loads(world["ug_info"])


def keep_world(world: bpy.types.World, params: str, info: dict) -> dict:
    """Record what ``world`` was built from (:func:`kept_world`); return ``info``."""
    world["ug_params"], world["ug_info"] = params, json.dumps(info)
    return info


def daylight_world(scene: bpy.types.Scene, *, sun_elevation_deg: float, sun_azimuth_deg: float,
                   sun_rgb: tuple, cloud_cover: float, cloud_seed: float, overcast: bool,
                   overcast_irradiance: float) -> dict:
    """Build the world of a day or dusk image and make it the scene's (kept if it already is, see
    :func:`kept_world`).

    Parameters
    ----------
    sun_elevation_deg, sun_azimuth_deg : float
        Sun position, degrees (azimuth a compass bearing, 0 = +y, 90 = +x); the elevation may
        be negative (twilight).
    sun_rgb : (3,) float
        Irradiance of the sun lamp on a surface facing it (W/m^2 in render units), per channel:
        lights the clouds' sunlit flanks.
    cloud_cover : float
        0..1 share of the sky under broken clouds (ignored when ``overcast``).
    cloud_seed : float
        Moves the cloud pattern.
    overcast : bool
        One closed deck instead of the physical sky.
    overcast_irradiance : float
        Horizontal irradiance the overcast deck gives (render units).

    Returns
    -------
    dict
        The sky's parameters for the image's metadata.
    """
    params = json.dumps([float(sun_elevation_deg), float(sun_azimuth_deg), [float(c) for c in sun_rgb],
                         float(cloud_cover), float(cloud_seed), bool(overcast), float(overcast_irradiance)])
    kept = kept_world(scene, "urbangen_sky", params)
    if kept is not None:
        return kept
    world = bpy.data.worlds.get("urbangen_sky") or bpy.data.worlds.new("urbangen_sky")
    g = Nodes(world.node_tree)
    d = g.coords("Generated")  # the view direction in a world shader
    x, y, z = _split(g, d)
    zc = g.math("MAXIMUM", z, 0.03)
    # the cloud-base plane, each frame's pattern a slice of 3D noise (cheaper than 4D)
    plane = _join(g, g.math("DIVIDE", x, zc), g.math("DIVIDE", y, zc), float(cloud_seed))
    bg = g.node("ShaderNodeBackground")
    g.set(bg.inputs["Strength"], 1.0)
    info = {"sun_elevation_deg": sun_elevation_deg, "sun_azimuth_deg": sun_azimuth_deg, "sky_strength": SKY_STRENGTH,
            "overcast": overcast}
    if overcast:
        lz = overcast_zenith(overcast_irradiance)
        grade = g.add(1.0 / 3.0, g.mul(g.math("MAXIMUM", z, 0.0), 2.0 / 3.0))
        texture = g.noise(g.mapping(plane, scale=(0.35, 0.35, 1.0)), scale=CLOUD_SCALE, detail=4, roughness=0.6)
        texture = g.add(0.8, g.mul(texture, 0.4))  # 0.8..1.2 around a mean of 1: the deck's structure
        g.set(bg.inputs["Color"], _scale_rgb(g, OVERCAST_TINT, g.mul(g.mul(grade, texture), lz)))
        plain = _scale_rgb(g, OVERCAST_TINT, g.mul(grade, lz))
        info.update(sky_model="cie_overcast", overcast_zenith_radiance=lz, overcast_irradiance=overcast_irradiance,
                    cloud_cover=1.0)
    else:
        sky = g.node("ShaderNodeTexSky", sky_type="MULTIPLE_SCATTERING")
        sky.sun_disc = False
        sky.sun_elevation = math.radians(sun_elevation_deg)
        # Blender's sky "sun rotation" is a compass bearing like ours (0 = +y, clockwise seen from above):
        # checked by aiming a camera at the lamp's direction and finding the sky's sun disc at the centre.
        sky.sun_rotation = math.radians(sun_azimuth_deg)
        sky.altitude = 0.0
        sky.air_density = 1.0
        sky.aerosol_density = 1.0
        sky_rgb = _scale_rgb(g, sky.outputs["Color"], SKY_STRENGTH)
        if cloud_cover <= 0.0:  # a cloudless sky: no cloud nodes to evaluate
            g.set(bg.inputs["Color"], sky_rgb)
            info.update(sky_model="blender_multiple_scattering", cloud_cover=0.0)
            g.output(bg.outputs[0], "ShaderNodeOutputWorld")
            scene.world = world
            return keep_world(world, params, info)
        zen = g.node("ShaderNodeTexSky", sky_type="MULTIPLE_SCATTERING")
        for k in ("sun_disc", "sun_elevation", "sun_rotation", "altitude", "air_density", "aerosol_density"):
            setattr(zen, k, getattr(sky, k))
        g.set(zen.inputs["Vector"], (0.0, 0.0, 1.0))
        zenith = _scale_rgb(g, zen.outputs["Color"], SKY_STRENGTH * CLOUD_SHADE)
        noise = g.noise(plane, scale=CLOUD_SCALE, detail=4, roughness=0.55)
        threshold = 0.72 - 0.44 * float(cloud_cover)
        density = g.smooth(noise, threshold - 0.02, threshold + 0.09)
        # thin out toward the horizon (haze) and in a gap around the sun
        density = g.mul(density, g.smooth(z, 0.0, 0.04))
        el, az = math.radians(sun_elevation_deg), math.radians(sun_azimuth_deg)
        sun_dir = (math.sin(az) * math.cos(el), math.cos(az) * math.cos(el), math.sin(el))
        cos_to_sun = _vmath(g, "DOT_PRODUCT", d, sun_dir, out=1)
        gap = g.smooth(cos_to_sun, math.cos(math.radians(SUN_GAP_DEG[1])), math.cos(math.radians(SUN_GAP_DEG[0])))
        density = g.mul(density, g.math("SUBTRACT", 1.0, gap))
        # lit flanks: the sun's light on the cloud, more where the noise is thin (edges) and toward the sun
        lit_share = g.mul(g.math("SUBTRACT", 1.0, g.smooth(noise, threshold, threshold + 0.25)),
                          g.add(0.5, g.mul(g.math("MAXIMUM", cos_to_sun, 0.0), 0.5)))
        lit = _scale_rgb(g, tuple(CLOUD_LIT / math.pi * c for c in sun_rgb), g.add(0.25, lit_share))
        cloud = g.mix(1.0, zenith, lit, "ADD")
        g.set(bg.inputs["Color"], g.mix(density, sky_rgb, cloud))
        plain = sky_rgb
        info.update(sky_model="blender_multiple_scattering+procedural_clouds", cloud_cover=float(cloud_cover),
                    cloud_seed=float(cloud_seed), cloud_sun_gap_deg=list(SUN_GAP_DEG))
    g.output(_seen_detail(g, bg.outputs[0], plain), "ShaderNodeOutputWorld")
    info["cloud_detail_rays"] = "camera and glossy (diffuse and shadow rays see the smooth sky)"
    scene.world = world
    return keep_world(world, params, info)


def _seen_detail(g: Nodes, detailed, plain_color):
    """Camera and glossy rays see ``detailed`` (clouds, the deck's texture); every other ray -- diffuse
    bounces, the world's importance map -- the smooth ``plain_color``. The cloud noise is then evaluated
    only where it is seen (a Mix Shader at 0 or 1 skips its other branch), and the light the town gets
    from a cloudy sky is its average, which is what the noise averages to."""
    lp = g.node("ShaderNodeLightPath")
    seen = g.math("MAXIMUM", lp.outputs["Is Camera Ray"], lp.outputs["Is Glossy Ray"])
    plain = g.node("ShaderNodeBackground")
    g.set(plain.inputs["Color"], plain_color)
    g.set(plain.inputs["Strength"], 1.0)
    return g.mix_shader(seen, plain.outputs[0], detailed)
