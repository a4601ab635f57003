"""Ground detail for the road, kerb, sidewalk and grass recipes (issue 29 item 2), as shading only.

Every pattern here is colour, roughness or bump: no geometry changes, so the label pass and the
LiDAR see exactly the triangles they saw before. Sizes are real (1 unit = 1 m):

* asphalt aggregate: stones of about 11 mm (a Voronoi cell per stone, a few pale quartz chips),
  binder tone varying over 1 m and 20 m;
* tar snakes: crack sealant, 1-3 cm wide meandering glossy lines (iso-lines of a 2.5 m noise) in
  patches of the road;
* gutter: the 0.6 m of carriageway by the kerb is grimy, collects fallen leaves and puddles first,
  with a gully grate (0.5 x 0.36 m) in 60 % of every 24 m of kerb. It needs the distance to the kerb,
  which the street object's ``ug_kerb_v`` (the kerb's offset from the segment's centre line, metres;
  set by :mod:`generator.blender.ground_tags`) gives in its segment frame; without it (0) there is
  no gutter;
* sidewalk: 0.6 m square slabs in the segment frame (joints along and square to the kerb), each a
  tone of its own and slightly tilted, dirt in the joints, chewing-gum spots, water stains;
* fallen leaves: 4-7 cm leaves in 14 cm cells, a share of the cells set by a density socket;
* grass: clumps, clover, dry straw-coloured patches and worn soil, blade-scale speckle.

Patterns that lie on the ground read only x and y (2D noise and Voronoi: a 3D Voronoi searches 27
cells, a 2D one 9, and the bump evaluates its height three times). World coordinates (``Position``)
for patterns that have no direction (grain, stains, leaves, grass),
so they run on across object borders without a seam; object coordinates where the pattern follows
the street (slabs, gutter, grates).
"""

from __future__ import annotations

from generator.blender.nodes import Nodes

STONE_CELLS_PER_M = 90.0       #: asphalt aggregate: Voronoi cells per metre (~11 mm stones)
SNAKE_SCALE, SNAKE_WIDTH = 0.4, 0.006  #: tar snakes: noise scale (1/m), iso-line half-width (noise units)
GUTTER_M = 0.6                 #: carriageway width by the kerb that is gutter
DRAIN_CELL_M, DRAIN_SHARE = 24.0, 0.6  #: one gully grate per 24 m of kerb, in 60 % of the cells
DRAIN_SIZE_M = (0.5, 0.36)     #: grate along the kerb x out from it
SLAB_M = 0.6                   #: sidewalk slab edge
LEAF_CELLS_PER_M = 5.0         #: fallen leaves: one candidate leaf per 20 cm cell


def xyz(g: Nodes, v):
    """Separate a vector socket into its (x, y, z) sockets."""
    sep = g.node("ShaderNodeSeparateXYZ")
    g.set(sep.inputs[0], v)
    return sep.outputs["X"], sep.outputs["Y"], sep.outputs["Z"]


def rgb(g: Nodes, c):
    """Separate a colour socket into its (r, g, b) sockets."""
    sep = g.node("ShaderNodeSeparateColor")
    g.set(sep.inputs[0], c)
    return sep.outputs[0], sep.outputs[1], sep.outputs[2]


def inv(g: Nodes, x):
    return g.math("SUBTRACT", 1.0, x)


def flat(g: Nodes, v):
    """``v`` with z = 0 (patterns on the ground plane)."""
    return g.mapping(v, scale=(1, 1, 0))


def aggregate(g: Nodes, wp, tone: float):
    """Asphalt stones and binder: (colour, height) sockets; ``wp`` world position."""
    chips = g.voronoi(wp, scale=STONE_CELLS_PER_M, out="Color", plane=True)
    c, _, _ = rgb(g, chips)
    stone = g.ramp(c, [(0.0, (tone * 0.55,) * 3), (0.8, (tone * 1.25,) * 3), (0.97, (tone * 1.6,) * 3),
                       (1.0, (tone * 3.5, tone * 3.4, tone * 3.2))])
    mid = g.noise(wp, scale=0.9, detail=3, plane=True)
    big = g.noise(wp, scale=0.045, detail=2, plane=True)
    tint = g.mul(g.add(0.75, g.mul(mid, 0.5)), g.add(0.8, g.mul(big, 0.4)))
    return g.mix(1.0, stone, tint, "MULTIPLY"), c


def tar_snakes(g: Nodes, wp):
    """0..1 mask of crack-sealant lines in about a third of the road."""
    n = g.noise(wp, scale=SNAKE_SCALE, detail=3, distortion=0.4, plane=True)
    line = inv(g, g.smooth(g.math("ABSOLUTE", g.math("SUBTRACT", n, 0.5)), SNAKE_WIDTH * 0.4, SNAKE_WIDTH))
    zone = g.smooth(g.noise(wp, scale=0.06, detail=1, plane=True), 0.5, 0.56)
    return g.mul(line, zone)


def gutter(g: Nodes, co):
    """(gutter 0..1 by the kerb, grate mask, grate slots) from the object's ``ug_kerb_v`` (segment frame)."""
    kerb = g.attr("ug_kerb_v", "OBJECT")
    x, y, _ = xyz(g, co)
    d = g.math("SUBTRACT", kerb, g.math("ABSOLUTE", y))            # metres to the kerb face
    has = g.math("GREATER_THAN", kerb, 0.0)
    wob = g.mul(g.noise(co, scale=1.2, detail=2, plane=True), 0.25)
    gut = g.mul(has, inv(g, g.smooth(g.add(d, wob), 0.25, GUTTER_M + 0.1)))
    # gully grates: one per DRAIN_CELL_M of each kerb, present by a hash of the cell and side
    cell = g.math("FLOOR", g.math("DIVIDE", x, DRAIN_CELL_M))
    side = g.math("SIGN", y)
    comb = g.node("ShaderNodeCombineXYZ")
    g.set(comb.inputs[0], cell)
    g.set(comb.inputs[1], side)
    g.set(comb.inputs[2], 3.7)
    hash_ = g.node("ShaderNodeTexWhiteNoise", noise_dimensions="3D")
    g.set(hash_.inputs["Vector"], comb.outputs[0])
    present = g.math("LESS_THAN", hash_.outputs["Value"], DRAIN_SHARE)
    du = g.math("ABSOLUTE", g.math("SUBTRACT", x, g.mul(g.add(cell, 0.5), DRAIN_CELL_M)))
    box = g.mul(inv(g, g.smooth(du, DRAIN_SIZE_M[0] / 2 - 0.004, DRAIN_SIZE_M[0] / 2)),
                g.mul(g.smooth(d, 0.05, 0.054), inv(g, g.smooth(d, 0.05 + DRAIN_SIZE_M[1] - 0.004,
                                                                 0.05 + DRAIN_SIZE_M[1]))))
    grate = g.mul(g.mul(present, has), box)
    inner = g.mul(inv(g, g.smooth(du, DRAIN_SIZE_M[0] / 2 - 0.04, DRAIN_SIZE_M[0] / 2 - 0.036)),
                  g.mul(g.smooth(d, 0.09, 0.094), inv(g, g.smooth(d, 0.37, 0.374))))
    bars = g.math("GREATER_THAN", g.math("FRACT", g.mul(x, 1 / 0.045)), 0.55)
    slots = g.mul(g.mul(grate, inner), bars)
    return gut, grate, slots


def leaves(g: Nodes, wp, density):
    """(leaf mask 0..1, leaf colour): fallen leaves in ``density`` (socket or constant) of the cells."""
    warp = g.mapping(g.noise(wp, scale=7.0, detail=1, out="Color", plane=True), scale=(0.08, 0.05, 0))
    p = g.node("ShaderNodeVectorMath", operation="ADD")
    g.set(p.inputs[0], wp)  # the 2D Voronoi reads x and y only
    g.set(p.inputs[1], warp)
    vor = g.node("ShaderNodeTexVoronoi", feature="F1", voronoi_dimensions="2D")
    g.set(vor.inputs["Vector"], p.outputs[0])
    vor.inputs["Scale"].default_value = LEAF_CELLS_PER_M
    r, gg, b = rgb(g, vor.outputs["Color"])
    size = g.add(0.2, g.mul(gg, 0.15))                                # radius in cell units (4-7 cm)
    shape = inv(g, g.smooth(g.math("DIVIDE", vor.outputs["Distance"], size), 0.85, 1.0))
    mask = g.mul(shape, g.math("LESS_THAN", r, density))
    col = g.ramp(b, [(0.0, (0.30, 0.17, 0.02)), (0.35, (0.28, 0.08, 0.015)), (0.7, (0.11, 0.055, 0.02)),
                     (1.0, (0.16, 0.14, 0.03))])
    return mask, col


def grid_cells(g: Nodes, v, scale, location=(0.0, 0.0, 0.0)):
    """Cells of a grid on ``v * scale + location`` (a Mapping): (white noise value and colour of the
    cell, x and y of the point inside its cell in [0, 1))."""
    grid = g.mapping(v, scale=scale, location=location)
    cell = g.node("ShaderNodeVectorMath", operation="FLOOR")
    g.set(cell.inputs[0], grid)
    frac = g.node("ShaderNodeVectorMath", operation="FRACTION")
    g.set(frac.inputs[0], grid)
    wn = g.node("ShaderNodeTexWhiteNoise", noise_dimensions="3D")
    g.set(wn.inputs["Vector"], cell.outputs[0])
    fx, fy, _ = xyz(g, frac.outputs[0])
    return wn.outputs["Value"], wn.outputs["Color"], fx, fy


def slabs(g: Nodes, co, tone: float):
    """Sidewalk slabs in object coordinates: (colour, joint mask, slab tilt height)."""
    xy = flat(g, co)
    joints = g.brick(xy, color1=(1, 1, 1), color2=(1, 1, 1), mortar=(0, 0, 0), scale=1.0, mortar_size=0.006,
                     brick_width=SLAB_M, row_height=SLAB_M, offset=0.0, out="Factor")
    _, colour, _, _ = grid_cells(g, xy, (1 / SLAB_M, 1 / SLAB_M, 0))
    r, gg, b = rgb(g, colour)
    shade = g.add(0.82, g.mul(r, 0.3))
    base = g.mul(shade, tone)
    x, y, _ = xyz(g, co)
    tilt = g.add(g.mul(g.math("FRACT", g.math("DIVIDE", x, SLAB_M)), g.math("SUBTRACT", gg, 0.5)),
                 g.mul(g.math("FRACT", g.math("DIVIDE", y, SLAB_M)), g.math("SUBTRACT", b, 0.5)))
    return base, joints, tilt


def stains(g: Nodes, wp):
    """(gum spots, water and rust stains) masks on paving, world coordinates."""
    vor = g.node("ShaderNodeTexVoronoi", feature="F1", voronoi_dimensions="2D")
    g.set(vor.inputs["Vector"], wp)
    vor.inputs["Scale"].default_value = 3.0
    r, _, _ = rgb(g, vor.outputs["Color"])
    gum = g.mul(g.math("LESS_THAN", r, 0.3), inv(g, g.smooth(vor.outputs["Distance"], 0.03, 0.045)))
    blot = g.mul(g.smooth(g.noise(wp, scale=0.7, detail=4), 0.55, 0.7), 0.6)
    return gum, blot


def grass(g: Nodes, wp, lush, dry):
    """Grass colour and bump height: clumps, clover, dry patches, worn soil; ``wp`` world position."""
    clump = g.noise(wp, scale=4.0, detail=2, plane=True)
    tone = g.noise(wp, scale=0.9, detail=4, plane=True)
    base = g.ramp(g.add(g.mul(tone, 0.7), g.mul(clump, 0.3)),
                  [(0.3, tuple(c * 0.6 for c in lush)), (0.5, lush), (0.7, tuple(c * 1.4 for c in lush))])
    dry_zone = g.smooth(g.noise(wp, scale=0.12, detail=3, plane=True), 0.55, 0.7)
    base = g.mix(g.mul(dry_zone, g.add(0.3, g.mul(clump, 0.6))), base, dry)
    clover = g.mul(g.smooth(g.noise(wp, scale=2.2, detail=2, plane=True), 0.62, 0.68), 0.6)
    base = g.mix(clover, base, (0.035, 0.07, 0.012))
    soil = g.smooth(g.noise(wp, scale=0.35, detail=4, plane=True), 0.7, 0.76)
    base = g.mix(g.mul(soil, 0.85), base, (0.085, 0.062, 0.04))
    blades = g.noise(wp, scale=160.0, detail=1, plane=True)
    base = g.mix(0.4, base, g.ramp(blades, [(0.3, (0.55,) * 3), (0.7, (1.45,) * 3)]), "MULTIPLY")
    return base, blades, soil
