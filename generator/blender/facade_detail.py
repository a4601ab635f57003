"""Facade surfaces for the wall recipes (issue 29 item 5), as shading only, at real scale.

No geometry changes here: the label pass and the LiDAR see the very triangles they saw before.
Walls are shaded in object coordinates (a building's local frame: metres, z up from the ground it
stands on); :func:`wall_uv` maps them to (metres along the wall, metres up) for axis-aligned walls,
continuous round a corner. Sizes:

* brick: 215 x 65 mm stretchers in 10 mm mortar joints (a 225 x 75 mm pitch), half-brick bond,
  every brick a tone of its own from a small palette (a few dark, over-burnt ones), recessed joints;
* render (plaster): 1-2 cm grain, blotches over a metre or two, an optional darker plinth 0.4-0.8 m
  high at the base;
* panels (concrete): joints on a 1.2-1.5 m grid (stack bond), every panel a tone of its own;
* weathering, on every wall: run-off streaks (a few cm wide, a metre or more long, in patches; densest
  under the sills of each storey), splash grime at the base fading out within ~0.5-1.2 m.

How weathered a building is comes per object from Object Info > Random (a hash of the object's
name: the same town gives the same values).
"""

from __future__ import annotations

from generator.blender.nodes import Nodes

BRICK_M = (0.225, 0.075)      #: brick pitch along and up: 215 x 65 mm bricks and a 10 mm joint
BRICK_JOINT_M = 0.010
PANEL_JOINT_M = 0.012
SILL_M = 0.87                 #: sill height above a storey's floor (the layouts draw 0.8-0.95 m)
STREAK_CELL_M = 0.22          #: run-off streak width scale (noise 1/scale along the wall), metres


def xyz(g: Nodes, v):
    sep = g.node("ShaderNodeSeparateXYZ")
    g.set(sep.inputs[0], v)
    return sep.outputs["X"], sep.outputs["Y"], sep.outputs["Z"]


def inv(g: Nodes, x):
    return g.math("SUBTRACT", 1.0, x)


def grey(g: Nodes, x):
    """A colour socket (x, x, x) of a float socket."""
    comb = g.node("ShaderNodeCombineColor")
    for i in range(3):
        g.set(comb.inputs[i], x)
    return comb.outputs[0]


def wall_uv(g: Nodes):
    """(vector (u, z, 0) in metres along the wall and up, object coordinates, z socket)."""
    co = g.coords("Object")
    x, y, z = xyz(g, co)
    comb = g.node("ShaderNodeCombineXYZ")
    g.set(comb.inputs[0], g.add(x, y))
    g.set(comb.inputs[1], z)
    return comb.outputs[0], co, z


def per_building(g: Nodes, k: float):
    """A value in [0, 1) per object (digit ``k`` of Object Info > Random)."""
    return g.math("FRACT", g.mul(g.object_info("Random"), k))


def cells(g: Nodes, uv, width: float, height: float, joint: float, offset: float):
    """Brick-texture cells of ``width`` x ``height`` metres with joints ``joint`` wide.

    Returns (per-cell random value in [0, 1] (a float socket), joint mask (1 in the joint)).
    The Brick texture puts ``mortar size`` on either side of an edge, so it is half the joint.
    """
    n = g.node("ShaderNodeTexBrick", offset=offset)
    g._inputs(n, {"vector": uv, "color1": (0, 0, 0), "color2": (1, 1, 1), "mortar": (0, 0, 0), "scale": 1.0,
                  "mortar_size": joint / 2, "mortar_smooth": 0.2, "bias": 0.0, "brick_width": width,
                  "row_height": height}, {"color1": "Color1", "color2": "Color2"})
    sep = g.node("ShaderNodeSeparateColor")
    g.set(sep.inputs[0], n.outputs["Color"])
    return sep.outputs[0], n.outputs["Factor"]


def brick(g: Nodes, uv, co, palette):
    """Brick wall colour and height: ``palette`` four colours (dark, mid, light, over-burnt)."""
    t, joint = cells(g, uv, BRICK_M[0], BRICK_M[1], BRICK_JOINT_M, 0.5)
    col = g.ramp(t, [(0.0, palette[0]), (0.45, palette[1]), (0.88, palette[2]), (0.93, palette[3])])
    grain = g.noise(co, scale=45.0, detail=1)
    col = g.mix(g.mul(g.math("ABSOLUTE", g.math("SUBTRACT", grain, 0.5)), 0.6), col, (0.06, 0.03, 0.02))
    col = g.mix(joint, col, (0.36, 0.345, 0.32))
    height = g.add(g.mul(joint, -1.0), g.mul(grain, 0.15))
    return col, height


def render(g: Nodes, uv, co, z, colour):
    """Rendered wall: grain, blotches, a plinth at the base on some buildings; (colour, height)."""
    grain = g.noise(co, scale=70.0, detail=1)
    blotch = g.noise(co, scale=0.7, detail=2)
    tone = g.add(0.94, g.add(g.mul(grain, 0.06), g.mul(g.smooth(blotch, 0.3, 0.7), 0.06)))
    col = g.mix(1.0, colour, grey(g, tone), "MULTIPLY")
    plinth_h = g.add(0.4, g.mul(per_building(g, 13.0), 0.4))
    has = g.math("GREATER_THAN", per_building(g, 7.0), 0.45)
    below = g.mul(has, inv(g, g.math("GREATER_THAN", z, plinth_h)))
    col = g.mix(below, col, g.mix(0.6, col, (0.32, 0.31, 0.3), "MULTIPLY"))
    return col, g.add(g.mul(grain, 0.5), g.mul(below, 0.3))


def panels(g: Nodes, uv, co, colour, size):
    """Concrete panel wall: stack-bonded ``size`` = (w, h) metre panels, a tone each; (colour, height)."""
    t, joint = cells(g, uv, size[0], size[1], PANEL_JOINT_M, 0.0)
    pores = g.noise(co, scale=60.0, detail=1)
    tone = g.add(0.88, g.add(g.mul(t, 0.16), g.mul(pores, 0.05)))
    col = g.mix(1.0, colour, grey(g, tone), "MULTIPLY")
    col = g.mix(g.mul(joint, 0.85), col, (0.12, 0.12, 0.12))
    return col, g.add(g.mul(joint, -1.0), g.mul(pores, 0.3))


def weathering(g: Nodes, uv, co, z, col, amount, floor_m: float = 3.2):
    """Age over a wall colour ``col``: a blotchy greying over metres, run-off streaks (densest in the
    metre under each storey's sills) and base grime; ``amount`` (0..1 socket or float).

    Returns (colour, stain height for the bump)."""
    u, v, _ = xyz(g, uv)
    broad = g.noise(co, scale=0.18, detail=2)               # ~5 m blotches: one noise for age and patches
    col = g.mix(g.mul(g.smooth(broad, 0.35, 0.75), g.mul(amount, 0.45)), col,
                g.mix(0.6, col, (0.42, 0.41, 0.39), "MULTIPLY"))
    st_vec = g.node("ShaderNodeCombineXYZ")
    g.set(st_vec.inputs[0], g.mul(u, 1.0 / STREAK_CELL_M))
    g.set(st_vec.inputs[1], g.mul(v, 0.35))
    streak = g.smooth(g.noise(st_vec.outputs[0], scale=1.0, detail=2, roughness=0.6), 0.5, 0.68)
    in_storey = g.math("FRACT", g.mul(g.math("SUBTRACT", SILL_M, v), 1.0 / floor_m))  # 0 at a sill, 1 a storey down
    fade = g.add(0.3, g.mul(inv(g, g.smooth(in_storey, 0.0, 0.45)), 0.7))
    k = g.mul(g.mul(streak, g.smooth(broad, 0.25, 0.6)), g.mul(fade, amount))
    col = g.mix(g.math("MINIMUM", g.mul(k, 1.1), 0.85), col, g.mix(0.75, col, (0.3, 0.28, 0.25), "MULTIPLY"))
    # base grime: splash and soil up to 0.5-1.2 m, ragged
    edge = g.add(0.5, g.mul(g.noise(co, scale=1.5, detail=1), 0.7))
    low = inv(g, g.smooth(g.math("DIVIDE", z, edge), 0.0, 1.0))
    grime = g.mul(low, g.add(0.45, g.mul(amount, 0.5)))
    col = g.mix(grime, col, g.mix(0.6, col, (0.28, 0.25, 0.2), "MULTIPLY"))
    return col, g.mul(k, 0.3)


def wavy_normal(g: Nodes, tilt: float = 0.02):
    """The surface normal tilted a little per pane (Random Per Island), as real panes are set: each
    reflects its own piece of the sky and street."""
    r = g.geometry("Random Per Island")
    comb = g.node("ShaderNodeCombineXYZ")
    for i, k in enumerate((1.0, 17.0, 131.0)):
        g.set(comb.inputs[i], g.mul(g.math("SUBTRACT", g.math("FRACT", g.mul(r, k)), 0.5), 2 * tilt))
    add = g.node("ShaderNodeVectorMath", operation="ADD")
    g.set(add.inputs[0], g.geometry("Normal"))
    g.set(add.inputs[1], comb.outputs[0])
    norm = g.node("ShaderNodeVectorMath", operation="NORMALIZE")
    g.set(norm.inputs[0], add.outputs[0])
    return norm.outputs[0]
