"""Road wear for the asphalt recipes: repair patches, sealed seams, manhole covers, oil stains.

Shader-side only: the road keeps its geometry and its class (``road``), so LiDAR labels and
lane markings are untouched; the camera sees a used street instead of spotless asphalt.
"""

from __future__ import annotations

import numpy as np

from generator.blender.ground_detail import grid_cells
from generator.blender.nodes import Nodes

PATCH_CELL_M = (4.5, 3.2)     #: repair patch grid (a patch in a fraction of the cells)
PATCH_SHARE = 0.18
MANHOLE_CELL_M = (11.0, 7.0)  #: manhole grid
MANHOLE_SHARE = 0.5
MANHOLE_R_M = 0.32


def _vadd(g: Nodes, a, b):
    n = g.node("ShaderNodeVectorMath", operation="ADD")
    g.set(n.inputs[0], a)
    g.set(n.inputs[1], b)
    return n.outputs[0]


def road_wear(g: Nodes, co, base, tone: float, rng: np.random.Generator):
    """Repair patches, tar-sealed seams, oil stains, alligator cracks and manhole covers over an asphalt colour.

    Everything is in the road's object coordinates (metres, z up): patches are rectangles in
    a 4.5 m x 3.2 m cell grid, manholes are 0.32 m-radius discs in a 13 m x 9 m grid, each
    present in a random fraction of the cells (white noise of the cell index).

    Returns
    -------
    (colour socket, roughness socket, bump height socket)
    """
    def cells(size, offset):
        return grid_cells(g, co, (1 / size[0], 1 / size[1], 0.0), offset)

    def band(x, lo, hi, soft=0.004):
        return g.mul(g.smooth(x, lo - soft, lo + soft), g.math("SUBTRACT", 1.0, g.smooth(x, hi - soft, hi + soft)))

    # repair patches: a rectangle in ~18% of the cells, fresher (darker) or older (greyer); the
    # edges wander a few centimetres and the new asphalt feathers out over ~8 cm (soft edges)
    r, col, fx, fy = cells(PATCH_CELL_M, tuple(rng.uniform(0, 1, 3)))
    wob = g.mul(g.math("SUBTRACT", g.noise(co, scale=2.0, detail=3, plane=True), 0.5), 0.03)
    fx, fy = g.add(fx, wob), g.add(fy, wob)
    present = g.math("LESS_THAN", r, PATCH_SHARE)
    inside = g.mul(band(fx, 0.12, 0.82, 0.012), band(fy, 0.15, 0.8, 0.016))
    seam = g.math("SUBTRACT", g.mul(band(fx, 0.11, 0.83), band(fy, 0.14, 0.81)),
                  g.mul(band(fx, 0.12, 0.82), band(fy, 0.15, 0.8)))
    patch = g.mul(present, inside)
    patch_col = g.mix(g.math("GREATER_THAN", r, PATCH_SHARE / 2), (tone * 0.7,) * 3,
                      (tone * 1.6, tone * 1.55, tone * 1.5))
    out = g.mix(g.mul(patch, 0.85), base, patch_col)
    out = g.mix(g.mul(g.mul(present, seam), 0.6), out, (0.012, 0.012, 0.012))
    # oil and tyre stains: soft dark blotches, a little glossier
    stains = g.mul(g.smooth(g.noise(co, scale=0.35, detail=3, plane=True), 0.56, 0.68),
                   g.smooth(g.noise(co, scale=2.5, detail=3, plane=True), 0.3, 0.6))
    out = g.mix(g.mul(stains, 0.75), out, (tone * 0.35,) * 3)
    # alligator cracking in worn zones: a fine cell network on noise-warped coordinates
    warp = _vadd(g, co, g.mapping(g.noise(co, scale=1.5, detail=2, out="Color", plane=True), scale=(0.6, 0.6, 0)))
    net = g.math("SUBTRACT", 1.0, g.smooth(g.voronoi(warp, scale=1.6, feature="DISTANCE_TO_EDGE", plane=True),
                                            0.0, 0.025))
    zone = g.smooth(g.noise(co, scale=0.09, detail=2, plane=True), 0.6, 0.66)
    cracks = g.mul(net, zone)
    out = g.mix(g.mul(cracks, 0.85), out, (0.008, 0.008, 0.008))
    # manhole covers: a cast-iron disc with a grid in a concrete collar, in MANHOLE_SHARE of the cells
    m, _, mx, my = cells(MANHOLE_CELL_M, tuple(rng.uniform(0, 1, 3)))
    dx = g.mul(g.math("SUBTRACT", mx, 0.5), MANHOLE_CELL_M[0])
    dy = g.mul(g.math("SUBTRACT", my, 0.5), MANHOLE_CELL_M[1])
    dist = g.math("SQRT", g.add(g.mul(dx, dx), g.mul(dy, dy)))
    has = g.math("LESS_THAN", m, MANHOLE_SHARE)
    disc = g.mul(has, g.math("SUBTRACT", 1.0, g.smooth(dist, MANHOLE_R_M - 0.01, MANHOLE_R_M)))
    collar = g.mul(has, g.math("SUBTRACT", 1.0, g.smooth(dist, MANHOLE_R_M + 0.07, MANHOLE_R_M + 0.08)))
    grid = g.brick(g.mapping(co, scale=(1, 1, 0)), color1=(1, 1, 1), color2=(1, 1, 1), mortar=(0, 0, 0),
                   scale=1.0, mortar_size=0.012, brick_width=0.06, row_height=0.06, offset=0.0, out="Factor")
    iron = g.mix(g.mul(grid, 0.7), (0.12, 0.11, 0.1), (0.04, 0.038, 0.036))     # worn cast iron, dark grooves
    out = g.mix(collar, out, (0.13, 0.128, 0.12))                                  # concrete collar
    out = g.mix(disc, out, iron)
    rough = g.lerp(g.add(g.mul(stains, 0.35), g.mul(disc, 0.3)), 0.85, 0.5)
    height = g.add(g.mul(g.mul(disc, g.math("SUBTRACT", 1.0, grid)), -0.5), g.mul(g.mul(present, seam), 0.3))
    height = g.add(height, g.mul(cracks, -0.6))
    return out, rough, height
