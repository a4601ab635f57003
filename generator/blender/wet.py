"""The wet-surface modifier of the ground materials: darker, glossier, puddles with ripples.

Wetness and the puddle pattern are scene switches (``VIEW_LAYER`` attributes, see
:mod:`generator.blender.controls`). Cycles folds them to constants when it compiles the
shaders, so a dry render (wetness 0) pays nothing for the puddle network; a wet render
evaluates it at every camera hit and at every glossy bounce on the ground. The network is
built to stay cheap there:

* the puddle pattern is moved per image by shifting 3D texture coordinates with the puddle
  seed, not by the fourth (``W``) dimension: a 4D Voronoi visits 81 cells per lookup, a 3D
  one 27, and 4D noise costs about twice 3D noise;
* the ripples are one Voronoi's rings (``sin`` of the distance to the nearest raindrop
  centre), not the difference of two Voronoi fields;
* the bump node evaluates its height input three times (at the point and two offsets);
  its height is the ripple field alone (times wetness, so it folds away when dry) and the
  puddle mask enters through the bump's strength, so the puddle noise is evaluated once.
"""

from __future__ import annotations

import math

from generator.blender.controls import CONTROL
from generator.blender.nodes import Nodes

#: Darkening of a soaked surface (albedo times ``1 - 0.5 * DARKEN * mask`` as a multiply mix).
DARKEN = 0.55
#: Roughness of a soaked surface and of standing water.
WET_ROUGHNESS, PUDDLE_ROUGHNESS = 0.08, 0.02
#: Puddle pattern: noise scale (1/m) and the smoothstep window where ground turns to water.
PUDDLE_SCALE, PUDDLE_EDGE = 0.08, (0.56, 0.6)
#: Ripples: raindrop cells per metre, rings per metre of radius, bump strength and distance (m).
RIPPLE_CELLS, RIPPLE_RINGS, RIPPLE_STRENGTH, RIPPLE_DISTANCE = 6.0, 9.0, 0.15, 0.01
#: Water runs to the low parts: a ``low`` mask of 1 (a gutter) lifts the puddle noise by this much.
LOW_BIAS = 0.25


def _shifted_coords(g: Nodes, seed):
    """Object coordinates shifted by a seed-dependent offset (metres): a new pattern per seed.

    The offset is kept below 100 m (``fract``-free: ``seed`` is drawn in [0, 1000)) so float32
    coordinates keep millimetre precision.
    """
    comb = g.node("ShaderNodeCombineXYZ")
    g.set(comb.inputs[0], g.mul(seed, 0.0917))
    g.set(comb.inputs[1], g.mul(seed, 0.0613))
    g.set(comb.inputs[2], g.mul(seed, 0.0271))
    return g.mapping(g.coords("Object"), location=comb.outputs[0])


def wet_surface(g: Nodes, color, roughness, normal=None, puddles: bool = True, low=None):
    """Darken and gloss a ground surface by the scene's wetness; add puddles with ripples.

    Parameters
    ----------
    g : Nodes
        The material's node builder.
    color, roughness : socket or constant
        The dry albedo (RGB) and roughness.
    normal : socket, optional
        The dry shading normal (e.g. a bump of the surface grain).
    puddles : bool
        Standing water where the puddle noise is low (roads, sidewalks); off for paint,
        grass and soil, which only darken and gloss.
    low : socket, optional
        0..1, how low the surface lies (the gutter by the kerb): puddles form there first.

    Returns
    -------
    (color, roughness, normal)
        Sockets to feed a Principled BSDF.
    """
    wet = g.attr(CONTROL["wetness"], "VIEW_LAYER")
    mask = wet
    if puddles:
        co = _shifted_coords(g, g.attr(CONTROL["puddle_seed"], "VIEW_LAYER"))
        n = g.noise(co, scale=PUDDLE_SCALE, detail=3, roughness=0.6)
        if low is not None:
            n = g.add(n, g.mul(low, LOW_BIAS))
        water = g.smooth(n, *PUDDLE_EDGE)
        pud = g.mul(water, wet)
        drop = g.voronoi(co, scale=RIPPLE_CELLS)  # distance to the nearest raindrop centre, in cell units
        rings = g.math("SINE", g.mul(drop, 2 * math.pi * RIPPLE_RINGS / RIPPLE_CELLS))
        height = g.mul(g.mul(rings, 0.05), wet)  # folds to 0 (no bump) when dry
        normal = g.bump(height, strength=g.mul(water, RIPPLE_STRENGTH), distance=RIPPLE_DISTANCE, normal=normal)
        mask = g.math("MAXIMUM", wet, pud)
        roughness = g.lerp(pud, roughness, PUDDLE_ROUGHNESS)
    color = g.mix(g.mul(mask, DARKEN), color, g.mix(0.5, color, (0, 0, 0), "MULTIPLY"))
    roughness = g.lerp(g.mul(wet, 0.8), roughness, WET_ROUGHNESS)
    return color, roughness, normal
