"""The label-pass material: one scene state that yields the mask labels (proxies shown) and the
real surface (proxies seen through) without a re-sync of Cycles between the two.

Every camera sample's colour holds exact integer ids in the code of
:mod:`generator.labels.label_colour` (R, G: the surface the ray stopped at; B: the first label
proxy, if the ray hit one first), decoded there.

A proxy is transparent to rays through a pixel centre of the configured (1x) image and opaque
to every other ray. So, with the proxies visible:

* the 1x render is the real pass: R, G and the Z pass belong to the real geometry behind any
  proxy (a fully transparent surface does not write the depth pass), B gives the label;
* a ``k`` times supersampled render (``k`` odd) is the label pass: its off-centre samples stop
  at the proxies as the opaque proxies of the old label pass did, so the foliage behind a
  tree's hull is traced only by the 1/k**2 of rays through the pixel centres.

Both renders share material, visibility and BVH; only the resolution changes between them.
The Window texture coordinate tells a shader where on the image a ray is: ``frac(x * W)`` is
0.5 at the pixel centres of a ``W`` pixel wide image and at least 1/k away from it on every
other sample of a ``k`` times finer image (``k`` odd).
"""

from __future__ import annotations

from generator.blender.bpy_guard import bpy
from generator.blender.nodes import Nodes
from generator.labels.label_colour import CODE_BASE

LABEL_MATERIAL = "urbangen_label_v2"
#: Object custom property marking a label proxy (set by :func:`mark_proxies`).
PROXY_PROPERTY = "ug_label_proxy"
#: A sample counts as a pixel-centre ray when it is within this many (1x) pixels of the centre.
CENTRE_TOLERANCE_PX = 0.05
#: Proxies a pixel-centre ray may pass before Cycles stops it (a row of street-tree crowns).
MAX_PROXY_CROSSINGS = 128


def mark_proxies(objects) -> None:
    """Tag label-proxy objects so the label material can tell them from real ones (idempotent)."""
    for ob in objects:
        if ob.get(PROXY_PROPERTY) != 1.0:
            ob[PROXY_PROPERTY] = 1.0


def _centre_test(g: Nodes, axis: str, name: str):
    """1.0 where the sample lies on a pixel centre along ``axis`` of the 1x image, else 0.0."""
    sep = g.node("ShaderNodeSeparateXYZ")
    g.set(sep.inputs[0], g.coords("Window"))
    pixels = g.value(1.0)
    pixels.node.name = name
    off = g.math("ABSOLUTE", g.math("SUBTRACT", g.math("FRACT", g.mul(sep.outputs[axis], pixels)), 0.5))
    return g.math("LESS_THAN", off, CENTRE_TOLERANCE_PX)


def label_material(width: int, height: int) -> "bpy.types.Material":
    """The label override material for a ``width`` x ``height`` (1x) image (created once, resized in place)."""
    mat = bpy.data.materials.get(LABEL_MATERIAL)
    if mat is None:
        mat = bpy.data.materials.new(LABEL_MATERIAL)
        _build(Nodes(mat.node_tree))
        mat.cycles.emission_sampling = "NONE"
    nodes = mat.node_tree.nodes
    for name, value in (("pixels_x", width), ("pixels_y", height)):
        out = nodes[name].outputs[0]
        if out.default_value != float(value):  # only a real change may touch the depsgraph
            out.default_value = float(value)
    return mat


def _build(g: Nodes) -> None:
    proxy = g.attr(PROXY_PROPERTY, "OBJECT")
    cls, inst = g.attr("class_id"), g.object_info("Object Index")
    centre = g.mul(_centre_test(g, "X", "pixels_x"), _centre_test(g, "Y", "pixels_y"))
    first = g.math("LESS_THAN", g.node("ShaderNodeLightPath").outputs["Transparent Depth"], 0.5)
    code = g.mul(g.add(cls, g.mul(inst, float(CODE_BASE))), first)
    opaque = g.math("SUBTRACT", 1.0, centre)
    real_ids = g.node("ShaderNodeCombineXYZ")
    g.set(real_ids.inputs[0], cls)
    g.set(real_ids.inputs[1], inst)
    proxy_ids = g.node("ShaderNodeCombineXYZ")
    g.set(proxy_ids.inputs[0], g.mul(cls, opaque))
    g.set(proxy_ids.inputs[1], g.mul(inst, opaque))
    g.set(proxy_ids.inputs[2], code)
    glow = g.emission(proxy_ids.outputs[0], 1.0)
    clear = g.node("ShaderNodeBsdfTransparent").outputs[0]
    seen_through = g.mix_shader(centre, glow, g.add_shader(g.emission(proxy_ids.outputs[0], 1.0), clear))
    g.output(g.mix_shader(proxy, g.emission(real_ids.outputs[0], 1.0), seen_through))
