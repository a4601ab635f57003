"""Recipes for the street-variety materials of issue 13: regulatory sign faces and block paving.

Same contract as :mod:`generator.blender.recipes` (one function per material name in
``generator/materials.yaml``, receiving a :class:`Nodes` builder and a seeded generator,
returning a shader socket); :func:`generator.blender.materials.build_materials` looks a name
up here when the other recipe modules have none of that name.
"""

from __future__ import annotations

import numpy as np

from generator.blender.nodes import Nodes
from generator.blender.recipes import _jit
from generator.blender.wet import wet_surface

#: linear-light colours of the retroreflective sign sheeting (RAL 5017 traffic blue, 3020 traffic red)
SIGN_BLUE = (0.0, 0.105, 0.262)
SIGN_RED = (0.60, 0.004, 0.003)
SIGN_WHITE = (0.80, 0.80, 0.78)
#: concrete block pavers of a shared street: 20 x 10 cm blocks in stretcher bond, joints 4 mm
BLOCK_M = (0.20, 0.10)
PAVER_RED = (0.20, 0.075, 0.055)
PAVER_GREY = (0.17, 0.155, 0.145)


def _sheeting(g: Nodes, rng: np.random.Generator, color):
    return g.principled(base_color=_jit(rng, color, 0.04), roughness=0.35, specular=0.8)


def sign_blue(g, rng):
    """The blue face of a "one way" sign."""
    return _sheeting(g, rng, SIGN_BLUE)


def sign_red(g, rng):
    """The red face of a "no entry" sign."""
    return _sheeting(g, rng, SIGN_RED)


def sign_symbol(g, rng):
    """The white arrow or bar on a regulatory sign."""
    return _sheeting(g, rng, SIGN_WHITE)


def block_paving(g: Nodes, rng: np.random.Generator):
    """Small concrete block pavers (a shared street's carriageway): red-brown and grey blocks in
    stretcher bond along the street (object x), each block its own tint, dark sanded joints, a
    slight bevel, worn paler where wheels run (large-scale noise), wet like the other ground."""
    co = g.coords("Object")
    xy = g.mapping(co, scale=(1, 1, 0))
    red, grey = _jit(rng, PAVER_RED, 0.08), _jit(rng, PAVER_GREY, 0.06)
    blocks = g.brick(xy, color1=red, color2=grey, mortar=(0.04, 0.04, 0.04), scale=1.0, mortar_size=0.004,
                     brick_width=BLOCK_M[0], row_height=BLOCK_M[1], offset=0.5)
    joints = g.brick(xy, color1=(1, 1, 1), color2=(1, 1, 1), mortar=(0, 0, 0), scale=1.0, mortar_size=0.006,
                     brick_width=BLOCK_M[0], row_height=BLOCK_M[1], offset=0.5, out="Factor")
    grain = g.noise(co, scale=60, detail=3)
    wear = g.noise(co, scale=0.3, detail=2)
    base = g.mix(g.mul(g.smooth(wear, 0.5, 0.75), 0.35), blocks, (0.24, 0.22, 0.2))
    base = g.mix(g.mul(grain, 0.2), base, (0.1, 0.09, 0.085))
    relief = g.add(g.mul(joints, -1.0), g.mul(grain, 0.1))          # joints sunk, faces slightly rough
    color, rough, normal = wet_surface(g, base, 0.85, g.bump(relief, 0.35, 0.004))
    return g.principled(base_color=color, roughness=rough, normal=normal)
