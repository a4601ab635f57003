"""Procedural material recipes, one function per name in ``generator/materials.yaml``.

Each recipe receives a :class:`Nodes` builder, a parameter generator (seeded per
material, so every seed gives a slightly different town) and returns the surface
shader socket. Scene-wide switches are scene custom properties read with
``VIEW_LAYER`` attributes (see :mod:`generator.blender.controls`); per-object colour
is ``Object.color`` (Object Info > Color); per-pane and per-leaf-cluster variation uses
Cycles' "Random Per Island" (every window pane and leaf cluster is its own island).
Vehicle paint and people (their colours come per object) are in :mod:`recipes_actors`.
"""

from __future__ import annotations

import numpy as np

from generator.blender import facade_detail as fd
from generator.blender import ground_detail as gd
from generator.blender.car_seam_shader import headlamp_inside
from generator.blender.controls import CONTROL
from generator.blender.nodes import Nodes
from generator.blender.road_surface import road_wear
from generator.blender.wet import wet_surface


def _jit(rng: np.random.Generator, base, spread: float):
    base = np.asarray(base, float)
    return tuple(np.clip(base * (1 + rng.uniform(-spread, spread, base.shape)), 0, 1))


def _emit(g: Nodes, shader, color, strength: float, group: str, factor=1.0):
    on = g.mul(g.attr(CONTROL["light_" + group], "VIEW_LAYER"), factor)
    return g.add_shader(shader, g.emission(color, g.mul(on, strength)))


def asphalt(g: Nodes, rng, tone=0.055, wear=0.5):
    """Asphalt: aggregate, patches, tar snakes, cracks, stains, manholes; by the kerb a gutter with
    grime, leaves and gully grates, where the water pools first (:mod:`generator.blender.ground_detail`)."""
    co, wp = g.coords("Object"), g.geometry("Position")
    tone = tone * rng.uniform(0.85, 1.2)
    base, stone = gd.aggregate(g, wp, tone)
    patches = g.noise(wp, scale=0.06, detail=3, plane=True)
    base = g.mix(g.mul(g.smooth(patches, 0.45, 0.6), wear), base, (tone * 1.8, tone * 1.75, tone * 1.7))
    snakes = gd.tar_snakes(g, wp)
    base = g.mix(g.mul(snakes, 0.9), base, (0.012, 0.012, 0.012))
    base, rough, worn = road_wear(g, co, base, tone, rng)
    gut, grate, slots = gd.gutter(g, co)
    leaf, leaf_col = gd.leaves(g, wp, g.mul(gut, 0.6))
    grime = g.mul(gut, g.add(0.6, g.mul(g.noise(wp, scale=3.0, detail=3, plane=True), 0.4)))
    base = g.mix(grime, base, (tone * 3.2, tone * 2.8, tone * 2.1))         # dusty sediment
    base = g.mix(g.mul(grime, g.smooth(g.noise(wp, scale=0.8, detail=2, plane=True), 0.45, 0.6)), base,
                 (tone * 0.4, tone * 0.36, tone * 0.28))                     # and dark wet-dirt stains
    base = g.mix(leaf, base, leaf_col)
    base = g.mix(grate, base, g.mix(slots, (0.07, 0.065, 0.06), (0.004, 0.004, 0.004)))
    rough = g.lerp(g.mul(snakes, 0.7), rough, 0.6)
    rough = g.lerp(grate, rough, 0.45)
    height = g.add(g.add(g.mul(stone, 0.6), worn), g.add(g.mul(snakes, 0.4), g.mul(slots, -1.5)))
    color, rough, normal = wet_surface(g, base, rough, g.bump(height, 0.25, 0.01), low=gut)
    return g.principled(base_color=color, roughness=rough, normal=normal)


def parking_asphalt(g, rng):
    return asphalt(g, rng, tone=0.075, wear=0.8)


def _paint(g, rng, color):
    """Road paint, worn: thinner in wheel-worn blotches (the asphalt shows through), dirty, speckled
    where the aggregate's tips poke through."""
    co, wp = g.coords("Object"), g.geometry("Position")
    dirt = g.noise(co, scale=3, detail=4)
    base = g.mix(g.mul(g.smooth(dirt, 0.5, 0.8), 0.5), _jit(rng, color, 0.05), (0.35, 0.35, 0.33))
    worn = g.smooth(g.noise(wp, scale=1.4, detail=5, roughness=0.65), 0.52, 0.7)
    chips = g.math("GREATER_THAN", g.noise(wp, scale=70, detail=1), 0.62)
    base = g.mix(g.math("MAXIMUM", g.mul(worn, 0.85), g.mul(chips, 0.6)), base, (0.05, 0.05, 0.05))
    col, rough, normal = wet_surface(g, base, 0.55, None, puddles=False)
    return g.principled(base_color=col, roughness=rough)


def lane_paint(g, rng):
    return _paint(g, rng, (0.75, 0.75, 0.72))


def crosswalk_paint(g, rng):
    return _paint(g, rng, (0.8, 0.8, 0.78))


def _concrete(g, rng, tone, slabs: bool):
    co, wp = g.coords("Object"), g.geometry("Position")
    n = g.noise(wp, scale=25, detail=5)
    base = g.ramp(n, [(0.35, _jit(rng, (tone * 0.85,) * 3, 0.05)), (0.65, _jit(rng, (tone * 1.1,) * 3, 0.05))])
    height = g.mul(n, 0.4)
    if slabs:   # sidewalk: 0.6 m slabs, dirty joints, gum, stains, fallen leaves (ground_detail)
        slab, joints, tilt = gd.slabs(g, co, 1.0)
        base = g.mix(1.0, base, slab, "MULTIPLY")
        base = g.mix(g.mul(joints, 0.9), base, (tone * 0.3, tone * 0.28, tone * 0.25))
        gum, blot = gd.stains(g, wp)
        base = g.mix(blot, base, g.mix(0.5, base, (0.55, 0.5, 0.42), "MULTIPLY"))
        base = g.mix(g.mul(gum, 0.8), base, (tone * 0.45,) * 3)
        leaf, leaf_col = gd.leaves(g, wp, g.mul(g.smooth(g.noise(wp, scale=0.2, detail=2), 0.55, 0.8), 0.6))
        base = g.mix(leaf, base, leaf_col)
        height = g.add(g.add(height, g.mul(joints, -1.2)), g.mul(tilt, 0.25))
    else:       # kerb: road grime on its lower face (object z from the road surface), weathering
        _, _, z = gd.xyz(g, co)
        low = g.mul(gd.inv(g, g.smooth(z, 0.02, 0.1)), g.add(0.4, g.mul(g.noise(wp, scale=4, detail=3), 0.6)))
        base = g.mix(low, base, (tone * 0.35, tone * 0.32, tone * 0.27))
        base = g.mix(g.mul(g.smooth(g.noise(wp, scale=1.3, detail=4), 0.55, 0.75), 0.5), base,
                     (tone * 0.6, tone * 0.58, tone * 0.52))
    col, rough, normal = wet_surface(g, base, 0.8, g.bump(height, 0.1, 0.01))
    return g.principled(base_color=col, roughness=rough, normal=normal)


def sidewalk_concrete(g, rng):
    return _concrete(g, rng, 0.42, slabs=True)


def curb_concrete(g, rng):
    return _concrete(g, rng, 0.5, slabs=False)


def grass(g, rng):
    """Grass that is not one green: clumps, clover, dry patches, worn soil, blades, a few leaves."""
    wp = g.geometry("Position")
    base, blades, soil = gd.grass(g, wp, _jit(rng, (0.075, 0.13, 0.03), 0.1), _jit(rng, (0.2, 0.17, 0.07), 0.1))
    leaf, leaf_col = gd.leaves(g, wp, g.mul(g.smooth(g.noise(wp, scale=0.2, detail=2, plane=True), 0.5, 0.8), 0.2))
    base = g.mix(leaf, base, leaf_col)
    col, rough, normal = wet_surface(g, base, 0.95, g.bump(g.add(blades, g.mul(soil, -0.5)), 0.4, 0.02),
                                     puddles=False)
    return g.principled(base_color=col, roughness=rough, normal=normal)


def soil(g, rng):
    n = g.noise(g.coords("Object"), scale=8, detail=6)
    base = g.ramp(n, [(0.3, (0.10, 0.07, 0.045)), (0.7, (0.16, 0.12, 0.08))])
    col, rough, normal = wet_surface(g, base, 0.95, g.bump(n, 0.3, 0.02), puddles=False)
    return g.principled(base_color=col, roughness=rough, normal=normal)


def _wall_coords(g):
    """(x + y, z) so axis-aligned walls map metres along the wall and up."""
    co = g.coords("Object")
    sep = g.node("ShaderNodeSeparateXYZ")
    g.set(sep.inputs[0], co)
    comb = g.node("ShaderNodeCombineXYZ")
    g.set(comb.inputs[0], g.add(sep.outputs["X"], sep.outputs["Y"]))
    g.set(comb.inputs[1], sep.outputs["Z"])
    return comb.outputs[0], co


def _tint(g, base):
    """Multiply a colour by the object's colour (``attrs['color']`` on the object)."""
    return g.mix(1.0, base, g.object_info("Color"), "MULTIPLY")


def _wall(g, col, height, rough, uv, co, z, weather=1.0):
    """Weathered wall shader of a base colour and height (:mod:`generator.blender.facade_detail`)."""
    amount = g.mul(g.add(0.35, g.mul(fd.per_building(g, 1.0), 0.65)), weather)
    col, stain = fd.weathering(g, uv, co, z, col, amount)
    return g.principled(base_color=col, roughness=g.add(rough, g.mul(stain, -0.1)),
                        normal=g.bump(g.add(height, stain), 0.3, 0.004))


def facade_plaster(g, rng):
    """Render: grain, blotches and water stains, a plinth on some buildings, weathering."""
    uv, co, z = fd.wall_uv(g)
    stains = g.smooth(g.noise(g.mapping(co, scale=(1, 1, 0.3)), scale=0.8, detail=2), 0.55, 0.75)
    base = g.mix(g.mul(stains, 0.25), (1.0, 1.0, 1.0), (0.8, 0.77, 0.72))
    col, height = fd.render(g, uv, co, z, _tint(g, base))
    return _wall(g, col, height, 0.9, uv, co, z)


#: the base wall tints of the layout (``generator/layout/lots/lot.py``): brick and concrete walls keep
#: only the per-building jitter of their tint (their colour is in the texture)
_BRICK_TINT, _CONCRETE_TINT = (0.6, 0.32, 0.24), (0.65, 0.65, 0.63)


def _rel_tint(g, base, tint):
    rel = g.mix(1.0, g.object_info("Color"), tuple(1.0 / c for c in tint), "MULTIPLY")
    return g.mix(1.0, base, rel, "MULTIPLY")


def facade_brick(g, rng):
    """Stretcher-bond brick at real size, a tone per brick, recessed mortar joints, weathering."""
    uv, co, z = fd.wall_uv(g)
    mid = np.asarray(_jit(rng, (0.3, 0.085, 0.048), 0.12))
    palette = [tuple(mid * 0.72), tuple(mid), tuple(np.clip(mid * [1.25, 1.35, 1.4], 0, 1)),
               tuple(mid * [0.45, 0.5, 0.6])]
    col, height = fd.brick(g, uv, co, palette)
    return _wall(g, _rel_tint(g, col, _BRICK_TINT), height, 0.85, uv, co, z)


def facade_concrete(g, rng):
    """Precast panels on a 1.2-1.5 m grid, a tone per panel, pores, weathering (stronger)."""
    uv, co, z = fd.wall_uv(g)
    size = (float(rng.uniform(1.2, 1.5)), float(rng.uniform(1.2, 1.5)))
    col, height = fd.panels(g, uv, co, _jit(rng, (0.4, 0.39, 0.37), 0.05), size)
    return _wall(g, _rel_tint(g, col, _CONCRETE_TINT), height, 0.8, uv, co, z, weather=1.2)


def window_glass(g, rng):
    lit_fraction = g.attr(CONTROL["lit_windows"], "VIEW_LAYER")
    # One draw per pane: every pane is its own mesh island (two triangles with their own vertices).
    pane = g.math("FRACT", g.add(g.geometry("Random Per Island"), g.object_info("Random")))
    lit = g.math("LESS_THAN", pane, lit_fraction)
    # Per lit room, from further digits of the pane's draw: a lamp colour from 2700 K to 6500 K
    # (mostly warm) and a brightness over 1.5 decades (curtains, lamps, ceiling lights).
    kelvin = g.math("FRACT", g.mul(pane, 37.0))
    warm = g.ramp(kelvin, [(0.0, (1.0, 0.62, 0.32)), (0.45, (1.0, 0.74, 0.46)), (0.75, (1.0, 0.86, 0.68)),
                           (0.92, (0.92, 0.94, 1.0))])
    bright = g.math("POWER", 10.0, g.add(-1.0, g.mul(g.math("FRACT", g.mul(pane, 113.0)), 1.5)))
    # the room behind: mostly dark, some panes with pale curtains or blinds drawn (a tone per pane)
    curtain = g.smooth(g.math("FRACT", g.mul(pane, 7.0)), 0.7, 0.95)
    room = g.mix(curtain, (0.012, 0.013, 0.015), g.mix(g.math("FRACT", g.mul(pane, 3.0)), (0.09, 0.08, 0.065),
                                                           (0.06, 0.065, 0.07)))
    glass = g.principled(base_color=room, roughness=g.add(0.015, g.mul(g.math("FRACT", g.mul(pane, 53.0)), 0.04)),
                         metallic=0.0, ior=1.5, specular=1.0, normal=fd.wavy_normal(g))
    return _emit(g, glass, warm, 6.0, "windows", g.mul(lit, bright))


def window_frame(g, rng):
    return g.principled(base_color=_jit(rng, (0.75, 0.75, 0.72), 0.05), roughness=0.5)


def roof(g, rng):
    uv, co = _wall_coords(g)
    tiles = g.brick(uv, color1=_jit(rng, (0.22, 0.08, 0.06), 0.2), color2=_jit(rng, (0.16, 0.06, 0.05), 0.2),
                    mortar=(0.05, 0.05, 0.05), scale=1.0, mortar_size=0.01, brick_width=0.3, row_height=0.22)
    n = g.noise(co, scale=10, detail=4)
    tint = g.attr("ug_roof_color", "OBJECT", "Color")
    return g.principled(base_color=g.mix(1.0, tiles, tint, "MULTIPLY"), roughness=0.75, normal=g.bump(n, 0.2, 0.01))


def door(g, rng):
    uv, co = _wall_coords(g)
    grain = g.wave(co, scale=2, distortion=6, detail=4, direction="Z")
    base = g.ramp(grain, [(0.2, (0.12, 0.06, 0.03)), (0.8, (0.2, 0.11, 0.06))])
    return g.principled(base_color=base, roughness=0.6)


def truck_paint(g, rng):
    return g.principled(base_color=g.object_info("Color"), metallic=0.1, roughness=0.45)


def rubber(g, rng):
    return g.principled(base_color=(0.015, 0.015, 0.015), roughness=0.9)


def chrome(g, rng):
    return g.principled(base_color=(0.8, 0.8, 0.82), metallic=1.0, roughness=0.15)


def headlight(g, rng):
    """A clear lens; on a car (``ug_seam_lamp``) chrome reflectors, two projector eyes and a black housing behind
    it (:func:`generator.blender.car_seam_shader.headlamp_inside`); lit at night on vehicles in use."""
    chrome, black, eye, on = headlamp_inside(g)
    base = g.mix(chrome, (0.8, 0.8, 0.8), (0.92, 0.92, 0.94))
    base = g.mix(black, base, (0.05, 0.05, 0.055))
    base = g.mix(eye, base, (0.02, 0.022, 0.028))
    metallic = g.lerp(black, g.lerp(chrome, 0.6, 1.0), 0.5)
    lens = g.principled(base_color=base, roughness=g.lerp(chrome, 0.1, 0.06), metallic=metallic, coat=on,
                        coat_roughness=0.02)   # the clear cover on a car's lamp; other vehicles keep the plain lens
    return _emit(g, lens, (1.0, 0.95, 0.85), 40.0, "vehicle_lights", g.attr("ug_lights_on", "OBJECT"))


def taillight(g, rng):
    lens = g.principled(base_color=(0.4, 0.02, 0.02), roughness=0.15)
    return _emit(g, lens, (1.0, 0.05, 0.02), 15.0, "vehicle_lights", g.attr("ug_lights_on", "OBJECT"))


def pole_metal(g, rng):
    n = g.noise(g.coords("Object"), scale=20, detail=3)
    base = g.ramp(n, [(0.3, _jit(rng, (0.18, 0.19, 0.2), 0.1)), (0.7, (0.26, 0.27, 0.28))])
    return g.principled(base_color=base, metallic=0.7, roughness=0.45)


def lamp_glass(g, rng):
    glass = g.principled(base_color=(0.8, 0.78, 0.7), roughness=0.2)
    return _emit(g, glass, (1.0, 0.8, 0.55), 60.0, "street_lamps")


def sign_face(g, rng):
    return g.principled(base_color=g.object_info("Color"), roughness=0.35, specular=0.8)


def sign_back(g, rng):
    return g.principled(base_color=(0.35, 0.36, 0.37), metallic=0.8, roughness=0.4)


def tl_housing(g, rng):
    return g.principled(base_color=(0.02, 0.02, 0.02), roughness=0.5)


def _signal(g, color, which: int):
    """A signal lamp, lit when the object's state (Object Info > Random in thirds) selects it."""
    state = g.math("FLOOR", g.mul(g.object_info("Random"), 3.0))
    lit = g.math("COMPARE", state, float(which))
    lens = g.principled(base_color=tuple(c * 0.06 for c in color), roughness=0.1)
    on = g.add(g.mul(lit, 0.98), 0.02)
    return _emit(g, lens, color, 30.0, "traffic_lights", on)


def tl_red(g, rng):
    return _signal(g, (1.0, 0.05, 0.02), 0)


def tl_amber(g, rng):
    return _signal(g, (1.0, 0.55, 0.02), 1)


def tl_green(g, rng):
    return _signal(g, (0.1, 1.0, 0.4), 2)


def fence_metal(g, rng):
    return g.principled(base_color=_jit(rng, (0.05, 0.07, 0.05), 0.2), metallic=0.6, roughness=0.5)


def fence_wood(g, rng):
    grain = g.wave(g.coords("Object"), scale=3, distortion=5, detail=4, direction="Z")
    base = g.ramp(grain, [(0.2, (0.2, 0.13, 0.07)), (0.8, (0.32, 0.22, 0.13))])
    return g.principled(base_color=base, roughness=0.8)


def default(g, rng):
    return g.principled(base_color=(0.3, 0.3, 0.3), roughness=0.7)
