"""Recipe of the city beyond the town (issue 29 item 6): ``far_facade``.

Same contract as :mod:`generator.blender.recipes`. The far city's buildings are plain boxes
(:mod:`generator.layout.ground.far_city`), all in one mesh; each box is its own mesh island, so
Cycles' "Random Per Island" gives every building its own wall colour and window draw. Walls map
metres along the wall (x + y: the boxes are axis-aligned) and up: a window 1.5 m x 1.6 m in every
3 m bay of every 3.2 m storey, glass dark and glossy by day, a share of the windows lit at night
(the ``windows`` light group and the scene's lit-window fraction, as the town's windows).
"""

from __future__ import annotations

import numpy as np

from generator.blender.controls import CONTROL
from generator.blender.nodes import Nodes
from generator.blender.recipes import _emit, _wall_coords

BAY_M, STOREY_M = 3.0, 3.2       #: window grid along the wall and up
WINDOW_M = (1.5, 1.6)            #: window width and height


def far_facade(g: Nodes, rng: np.random.Generator):
    uv, co = _wall_coords(g)
    bld = g.geometry("Random Per Island")
    wall = g.ramp(bld, [(0.0, (0.42, 0.36, 0.3)), (0.25, (0.55, 0.52, 0.46)), (0.5, (0.3, 0.13, 0.08)),
                        (0.7, (0.62, 0.6, 0.56)), (0.85, (0.25, 0.26, 0.27)), (1.0, (0.5, 0.45, 0.36))])
    cell = g.mapping(uv, scale=(1 / BAY_M, 1 / STOREY_M, 0))
    frac = g.node("ShaderNodeVectorMath", operation="FRACTION")
    g.set(frac.inputs[0], cell)
    sep = g.node("ShaderNodeSeparateXYZ")
    g.set(sep.inputs[0], frac.outputs[0])
    wx, wz = WINDOW_M[0] / BAY_M / 2, WINDOW_M[1] / STOREY_M / 2
    inx = g.math("LESS_THAN", g.math("ABSOLUTE", g.math("SUBTRACT", sep.outputs["X"], 0.5)), wx)
    inz = g.math("LESS_THAN", g.math("ABSOLUTE", g.math("SUBTRACT", sep.outputs["Y"], 0.55)), wz)
    window = g.mul(inx, inz)
    fl = g.node("ShaderNodeVectorMath", operation="FLOOR")
    g.set(fl.inputs[0], cell)
    wn = g.node("ShaderNodeTexWhiteNoise", noise_dimensions="4D")
    g.set(wn.inputs["Vector"], fl.outputs[0])
    g.set(wn.inputs["W"], g.mul(bld, 100.0))
    pane = wn.outputs["Value"]
    glass = g.mix(pane, (0.02, 0.025, 0.03), (0.06, 0.07, 0.08))
    base = g.mix(window, wall, glass)
    shader = g.principled(base_color=base, roughness=g.lerp(window, 0.85, 0.1))
    lit = g.mul(window, g.math("LESS_THAN", pane, g.attr(CONTROL["lit_windows"], "VIEW_LAYER")))
    warm = g.ramp(g.math("FRACT", g.mul(pane, 29.0)), [(0.0, (1.0, 0.62, 0.32)), (0.6, (1.0, 0.8, 0.55)),
                                                         (1.0, (0.9, 0.93, 1.0))])
    return _emit(g, shader, warm, 4.0, "windows", lit)
