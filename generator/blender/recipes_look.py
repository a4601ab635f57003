"""Recipes of trees (bark and foliage of every species) and facade details (issue 14 item 4, issue 29 item 1).

Same contract as :mod:`generator.blender.recipes` (one function per material name in
``generator/materials.yaml``, receiving a :class:`Nodes` builder and a seeded generator,
returning a shader socket); :func:`generator.blender.materials.build_materials` looks a
name up here when :mod:`recipes` has no recipe of that name.
"""

from __future__ import annotations

import numpy as np

from generator.blender import facade_detail as fd
from generator.blender.controls import CONTROL
from generator.blender.nodes import Nodes
from generator.blender.recipes import _emit, _jit, _tint, _wall_coords


def bark(g, rng):
    """Furrowed bark: vertical plates between dark cracks, grey-brown, a green film of algae in patches."""
    co = g.coords("Object")
    crack = g.smooth(g.voronoi(g.mapping(co, scale=(7.0, 7.0, 1.4)), scale=1.0, feature="DISTANCE_TO_EDGE"), 0.0, 0.09)
    grain = g.noise(g.mapping(co, scale=(30, 30, 6)), scale=1.0, detail=2)
    base = g.ramp(grain, [(0.25, _jit(rng, (0.07, 0.06, 0.05), 0.1)), (0.75, _jit(rng, (0.15, 0.135, 0.115), 0.1))])
    base = g.mix(g.mul(g.smooth(g.noise(co, scale=1.2, detail=2), 0.55, 0.75), 0.6), base, (0.06, 0.08, 0.03))
    base = g.mix(g.math("SUBTRACT", 1.0, crack), base, (0.015, 0.012, 0.01))
    return g.principled(base_color=base, roughness=0.92, normal=g.bump(crack, 0.8, 0.02))


def _foliage(g, rng, color):
    """Leaves: each leaf (mesh island) its own shade and a little its own hue, sunny and shaded
    sides of a crown; light through them from behind (a quarter translucent)."""
    leaf = g.geometry("Random Per Island")
    n = g.noise(g.coords("Object"), scale=0.8, detail=1)
    hue = g.add(g.add(0.46, g.mul(g.object_info("Random"), 0.06)), g.mul(leaf, 0.05))
    base = g.ramp(n, [(0.3, _jit(rng, color, 0.1)), (0.75, _jit(rng, np.asarray(color) * 1.5, 0.1))])
    base = g.hsv(base, hue=hue, value=g.add(0.6, g.mul(leaf, 0.8)))
    face = g.principled(base_color=base, roughness=0.55, specular=0.35)
    return g.mix_shader(0.25, face, g.translucent(base))


def leaves(g, rng):
    return _foliage(g, rng, (0.045, 0.09, 0.02))


def bark_birch(g: Nodes, rng: np.random.Generator):
    """White bark with dark horizontal lenticels."""
    co = g.coords("Object")
    marks = g.smooth(g.noise(g.mapping(co, scale=(9, 9, 0.9)), scale=2.5, detail=3), 0.62, 0.7)
    base = g.mix(marks, _jit(rng, (0.72, 0.7, 0.66), 0.04), (0.05, 0.045, 0.04))
    return g.principled(base_color=base, roughness=0.7, normal=g.bump(marks, 0.3, 0.01))


def leaves_birch(g, rng):
    return _foliage(g, rng, (0.07, 0.12, 0.025))


def needles(g, rng):
    return _foliage(g, rng, (0.02, 0.05, 0.022))


def facade_glass(g, rng):
    """Curtain-wall spandrels: dark tinted, glossy glass over a grid of panels (reflects the sky)."""
    uv, co = _wall_coords(g)
    panels = g.brick(uv, color1=(1, 1, 1), color2=(0.8, 0.85, 0.9), mortar=(0.25, 0.25, 0.25), scale=1.0,
                     mortar_size=0.015, brick_width=1.5, row_height=1.6, offset=0.0)
    tint = _jit(rng, (0.05, 0.075, 0.09), 0.2)
    base = g.mix(1.0, panels, tint, "MULTIPLY")
    return g.principled(base_color=base, roughness=0.08, metallic=0.6, specular=1.0)


def shop_glass(g, rng):
    """Shop windows: clear glass with a lit interior at night (the ``windows`` light group)."""
    pane = g.math("FRACT", g.add(g.geometry("Random Per Island"), g.object_info("Random")))
    lit = g.math("LESS_THAN", pane, g.add(g.attr(CONTROL["lit_windows"], "VIEW_LAYER"), 0.3))
    glass = g.principled(base_color=(0.015, 0.02, 0.022), roughness=0.02, ior=1.5, specular=1.0,
                         normal=fd.wavy_normal(g, 0.01))
    return _emit(g, glass, (1.0, 0.9, 0.75), 8.0, "windows", lit)


def awning(g, rng):
    """Striped fabric; the stripe colour is drawn per object (Object Info > Random)."""
    uv, co = _wall_coords(g)
    stripes = g.math("GREATER_THAN", g.wave(uv, scale=2.2, kind="BANDS", direction="X"), 0.5)
    hue = g.object_info("Random")
    colour = g.hsv((0.45, 0.06, 0.05), hue=g.add(0.2, hue), saturation=0.9, value=1.0)
    plain = g.math("GREATER_THAN", g.math("FRACT", g.mul(hue, 7.0)), 0.5)
    stripe = g.mix(g.mul(stripes, plain), colour, (0.8, 0.78, 0.72))
    return g.principled(base_color=stripe, roughness=0.85, sheen=0.3)


def shop_sign(g, rng):
    """Painted sign boards over the shop windows: a colour per board (each board is its own mesh
    island: Random Per Island, with the object's draw), pale lettering blocks along their middle."""
    uv, co = _wall_coords(g)
    board = g.math("FRACT", g.add(g.geometry("Random Per Island"), g.object_info("Random")))
    letters = g.brick(uv, color1=(1, 1, 1), color2=(1, 1, 1), mortar=(0, 0, 0), scale=1.0, mortar_size=0.05,
                      brick_width=0.35, row_height=0.55, out="Factor")
    colour = g.hsv((0.05, 0.1, 0.25), hue=board, saturation=g.add(0.5, g.mul(g.math("FRACT", g.mul(board, 7.0)), 0.6)),
                   value=g.add(0.6, g.mul(g.math("FRACT", g.mul(board, 13.0)), 0.8)))
    base = g.mix(g.mul(g.math("SUBTRACT", 1.0, letters), 0.85), colour, (0.85, 0.82, 0.75))
    return g.principled(base_color=base, roughness=0.4)


def balcony_metal(g, rng):
    return g.principled(base_color=_tint(g, _jit(rng, (0.12, 0.12, 0.125), 0.2)), metallic=0.6, roughness=0.45)


# -- issue 29 item 5 (facades): window surrounds, copings, drainpipes ----------------------------


def facade_trim(g, rng):
    """Stone or render trim (window surrounds, string courses, parapet copings): pale, fine grain,
    a little weathered."""
    uv, co, z = fd.wall_uv(g)
    grain = g.noise(co, scale=60.0, detail=2)
    col = g.mix(g.mul(grain, 0.15), _jit(rng, (0.72, 0.7, 0.65), 0.05), (0.55, 0.53, 0.5))
    col, stain = fd.weathering(g, uv, co, z, col, g.mul(fd.per_building(g, 1.0), 0.6))
    return g.principled(base_color=col, roughness=0.75, normal=g.bump(g.add(grain, stain), 0.2, 0.003))


def drainpipe(g, rng):
    """Painted metal rainwater pipes: dark grey, black or zinc per building, a little dirty."""
    pick = fd.per_building(g, 29.0)
    col = g.ramp(pick, [(0.0, (0.06, 0.06, 0.065)), (0.5, (0.2, 0.21, 0.22)), (0.8, (0.42, 0.43, 0.44))])
    dirt = g.smooth(g.noise(g.coords("Object"), scale=3.0, detail=3), 0.5, 0.7)
    col = g.mix(g.mul(dirt, 0.4), col, (0.12, 0.1, 0.08))
    return g.principled(base_color=col, metallic=0.4, roughness=0.5)


def bark_plane(g: Nodes, rng: np.random.Generator):
    """London plane bark: smooth, flaking in patches of cream, olive and grey-brown."""
    co = g.mapping(g.coords("Object"), scale=(3.0, 3.0, 1.6))
    patch = g.ramp(g.voronoi(co, scale=2.2, out="Color"),
                   [(0.25, _jit(rng, (0.16, 0.15, 0.1), 0.05)), (0.5, _jit(rng, (0.08, 0.08, 0.05), 0.05)),
                    (0.75, _jit(rng, (0.24, 0.22, 0.16), 0.05))])
    return g.principled(base_color=patch, roughness=0.75)


def hedge_leaves(g: Nodes, rng: np.random.Generator):
    """Clipped-hedge leaves: dark glossy old leaves, each its own shade (Random Per Island), and about
    one in eight tinged toward a light yellow-green new shoot; a soft per-hedge hue (Object Info > Random)."""
    leaf = g.geometry("Random Per Island")
    n = g.noise(g.coords("Object"), scale=1.5, detail=1)
    old = g.ramp(n, [(0.3, _jit(rng, (0.025, 0.06, 0.016), 0.1)), (0.75, _jit(rng, (0.045, 0.095, 0.025), 0.1))])
    old = g.hsv(old, hue=g.add(g.add(0.47, g.mul(g.object_info("Random"), 0.05)), g.mul(leaf, 0.04)),
                value=g.add(0.55, g.mul(leaf, 0.9)))
    young = g.mul(g.smooth(g.math("FRACT", g.mul(leaf, 7.0)), 0.84, 0.9), 0.7)
    base = g.mix(young, old, _jit(rng, (0.075, 0.12, 0.028), 0.1))
    face = g.principled(base_color=base, roughness=0.45, specular=0.45)
    return g.mix_shader(0.2, face, g.translucent(base))


def leaf_shade(g: Nodes, rng: np.random.Generator):
    """The inner body of a leaf cluster: leaves in each other's shade, dark and mottled leaf by leaf
    (Voronoi cells a leaf across, each domed by a bump, so the low-poly core shows leaves, not facets;
    no translucency: little light gets through a cluster)."""
    co = g.coords("Object")
    cell = g.voronoi(co, scale=9.0, out="Color")
    dome = cell.node.outputs["Distance"]                                       # the same cells' F1 distance
    tone = g.ramp(cell, [(0.0, _jit(rng, (0.02, 0.042, 0.011), 0.1)), (1.0, _jit(rng, (0.05, 0.09, 0.022), 0.1))])
    tone = g.mix(g.mul(g.noise(co, scale=2.0, detail=1), 0.5), tone, (0.015, 0.03, 0.008))
    tone = g.hsv(tone, hue=g.add(0.47, g.mul(g.object_info("Random"), 0.06)))
    bump = g.bump(g.math("SUBTRACT", 1.0, dome), 0.5, 0.02)
    return g.principled(base_color=tone, roughness=0.7, specular=0.25, normal=bump)


def hedge_body(g: Nodes, rng: np.random.Generator):
    """The inside of a hedge behind its leaf skin: small leaves packed edge to edge in deep shade
    (Voronoi cells a few centimetres across, each its own shade), darker still in the holes."""
    co = g.coords("Object")
    cell = g.voronoi(co, scale=22.0, out="Color")
    deep = g.smooth(g.noise(co, scale=3.0, detail=1), 0.35, 0.7)             # holes in the clipping
    tone = g.ramp(cell, [(0.0, _jit(rng, (0.012, 0.026, 0.007), 0.1)), (1.0, _jit(rng, (0.035, 0.07, 0.018), 0.1))])
    tone = g.mix(g.mul(deep, 0.7), tone, (0.006, 0.011, 0.004))
    tone = g.hsv(tone, hue=g.add(0.47, g.mul(g.object_info("Random"), 0.05)))
    return g.principled(base_color=tone, roughness=0.6, specular=0.3, normal=g.bump(deep, 0.5, 0.03))
