"""A small builder for shader node trees, so material recipes read as formulas.

Every method adds nodes to one tree and returns an output socket; arguments may be
sockets or constants. Example::

    g = Nodes(material.node_tree)
    n = g.noise(scale=40, detail=6)
    color = g.mix(n, (0.05, 0.05, 0.05), (0.12, 0.12, 0.12))
    g.output(g.principled(base_color=color, roughness=0.85))
"""

from __future__ import annotations

from generator.blender.bpy_guard import bpy

Socket = "bpy.types.NodeSocket"


def _is_socket(x) -> bool:
    return isinstance(x, bpy.types.NodeSocket)


def _rgba(v):
    if isinstance(v, (int, float)):
        return (float(v), float(v), float(v), 1.0)
    v = tuple(float(c) for c in v)
    return v + (1.0,) if len(v) == 3 else v


class Nodes:
    """Node-tree builder for one material, world or node group."""

    def __init__(self, tree: bpy.types.NodeTree, clear: bool = True):
        self.tree = tree
        if clear:
            tree.nodes.clear()

    # -- plumbing --------------------------------------------------------------------
    def node(self, kind: str, **props):
        n = self.tree.nodes.new(kind)
        for k, v in props.items():
            setattr(n, k, v)
        return n

    def set(self, sock, value) -> None:
        """Link ``value`` into input ``sock`` (a socket) or set its default (a constant)."""
        if _is_socket(value):
            self.tree.links.new(value, sock)
        elif sock.type == "RGBA":
            sock.default_value = _rgba(value)
        elif sock.type == "VECTOR":
            sock.default_value = tuple(float(c) for c in value)
        else:
            sock.default_value = value

    def _inputs(self, node, values: dict, names: dict | None = None) -> None:
        for key, value in values.items():
            if value is None:
                continue
            name = (names or {}).get(key, key.replace("_", " ").title())
            self.set(node.inputs[name], value)

    # -- inputs ----------------------------------------------------------------------
    def attr(self, name: str, kind: str = "GEOMETRY", out: str = "Factor"):
        """An attribute: GEOMETRY (mesh), OBJECT (object custom property), VIEW_LAYER (scene custom property)."""
        return self.node("ShaderNodeAttribute", attribute_type=kind, attribute_name=name).outputs[out]

    def object_info(self, out: str):
        return self.node("ShaderNodeObjectInfo").outputs[out]

    def coords(self, out: str = "Object"):
        return self.node("ShaderNodeTexCoord").outputs[out]

    def geometry(self, out: str):
        return self.node("ShaderNodeNewGeometry").outputs[out]

    def value(self, v: float):
        n = self.node("ShaderNodeValue")
        n.outputs[0].default_value = float(v)
        return n.outputs[0]

    # -- textures --------------------------------------------------------------------
    def noise(self, vector=None, scale=5.0, detail=2.0, roughness=0.5, distortion=0.0, out="Factor", w=None,
              plane=False):
        """Perlin noise; ``plane=True`` reads only the vector's x and y (a pattern on the ground plane:
        2D noise, about half the cost of 3D per octave)."""
        n = self.node("ShaderNodeTexNoise", noise_dimensions="4D" if w is not None else "2D" if plane else "3D")
        self._inputs(n, {"vector": vector, "scale": scale, "detail": detail, "roughness": roughness,
                         "distortion": distortion, "w": w}, {"w": "W"})
        return n.outputs[out]

    def voronoi(self, vector=None, scale=5.0, randomness=1.0, feature="F1", out="Distance", w=None, plane=False):
        """Voronoi cells; ``plane=True`` reads only the vector's x and y (cells on the ground plane: 2D,
        9 neighbour cells searched instead of 27)."""
        n = self.node("ShaderNodeTexVoronoi", feature=feature,
                      voronoi_dimensions="4D" if w is not None else "2D" if plane else "3D")
        self._inputs(n, {"vector": vector, "scale": scale, "randomness": randomness, "w": w}, {"w": "W"})
        return n.outputs[out]

    def brick(self, vector=None, color1=(0.5, 0.2, 0.1), color2=(0.4, 0.15, 0.08), mortar=(0.6, 0.6, 0.58),
              scale=1.0, mortar_size=0.02, brick_width=0.5, row_height=0.25, offset=0.5, out="Color"):
        n = self.node("ShaderNodeTexBrick", offset=offset)
        self._inputs(n, {"vector": vector, "color1": color1, "color2": color2, "mortar": mortar, "scale": scale,
                         "mortar_size": mortar_size, "brick_width": brick_width, "row_height": row_height},
                     {"color1": "Color1", "color2": "Color2"})
        return n.outputs[out]

    def wave(self, vector=None, scale=5.0, distortion=0.0, detail=2.0, kind="BANDS", direction="X", out="Factor"):
        n = self.node("ShaderNodeTexWave", wave_type=kind)
        if kind == "BANDS":
            n.bands_direction = direction
        self._inputs(n, {"vector": vector, "scale": scale, "distortion": distortion, "detail": detail})
        return n.outputs[out]

    def mapping(self, vector, scale=(1, 1, 1), location=(0, 0, 0)):
        n = self.node("ShaderNodeMapping")
        self._inputs(n, {"vector": vector, "scale": scale, "location": location})
        return n.outputs["Vector"]

    # -- maths and colour --------------------------------------------------------------
    def math(self, op: str, a, b=0.0, clamp: bool = False):
        n = self.node("ShaderNodeMath", operation=op, use_clamp=clamp)
        self.set(n.inputs[0], a)
        self.set(n.inputs[1], b)
        return n.outputs[0]

    def mul(self, a, b):
        return self.math("MULTIPLY", a, b)

    def add(self, a, b):
        return self.math("ADD", a, b)

    def smooth(self, x, lo: float, hi: float):
        """Smoothstep of ``x`` from ``lo`` to ``hi`` (a Map Range node)."""
        n = self.node("ShaderNodeMapRange", interpolation_type="SMOOTHSTEP")
        self.set(n.inputs["Value"], x)
        n.inputs["From Min"].default_value = lo
        n.inputs["From Max"].default_value = hi
        return n.outputs["Result"]

    def mix(self, factor, a, b, blend: str = "MIX"):
        """Mix two colours by ``factor``."""
        n = self.node("ShaderNodeMix", data_type="RGBA", blend_type=blend)
        ins = [s for s in n.inputs if s.type == "RGBA"]
        self.set(n.inputs[0], factor)
        self.set(ins[0], a)
        self.set(ins[1], b)
        return [s for s in n.outputs if s.type == "RGBA"][0]

    def lerp(self, factor, a, b):
        """Mix two floats by ``factor``."""
        n = self.node("ShaderNodeMix", data_type="FLOAT")
        self.set(n.inputs[0], factor)
        self.set(n.inputs[2], a)
        self.set(n.inputs[3], b)
        return n.outputs[0]

    def ramp(self, factor, stops: list[tuple[float, tuple]]):
        """A colour ramp with ``(position, colour)`` stops."""
        n = self.node("ShaderNodeValToRGB")
        els = n.color_ramp.elements
        while len(els) > len(stops):
            els.remove(els[-1])
        while len(els) < len(stops):
            els.new(0.5)
        for el, (pos, col) in zip(els, stops, strict=False):
            el.position = pos
            el.color = _rgba(col)
        self.set(n.inputs[0], factor)
        return n.outputs["Color"]

    def hsv(self, color, hue=0.5, saturation=1.0, value=1.0):
        n = self.node("ShaderNodeHueSaturation")
        self._inputs(n, {"color": color, "hue": hue, "saturation": saturation, "value": value})
        return n.outputs["Color"]

    def bump(self, height, strength=0.2, distance=0.05, normal=None):
        n = self.node("ShaderNodeBump")
        self._inputs(n, {"height": height, "strength": strength, "distance": distance, "normal": normal})
        return n.outputs["Normal"]

    # -- shaders ---------------------------------------------------------------------
    def principled(self, **inputs):
        """A Principled BSDF; keyword names are socket names in snake case (base_color, roughness...)."""
        n = self.node("ShaderNodeBsdfPrincipled")
        names = {"ior": "IOR", "coat_ior": "Coat IOR", "specular": "Specular IOR Level",
                 "transmission": "Transmission Weight", "coat": "Coat Weight", "subsurface": "Subsurface Weight",
                 "sheen": "Sheen Weight"}
        self._inputs(n, inputs, names)
        return n.outputs["BSDF"]

    def emission(self, color, strength):
        n = self.node("ShaderNodeEmission")
        self._inputs(n, {"color": color, "strength": strength})
        return n.outputs[0]

    def add_shader(self, a, b):
        n = self.node("ShaderNodeAddShader")
        self.tree.links.new(a, n.inputs[0])
        self.tree.links.new(b, n.inputs[1])
        return n.outputs[0]

    def mix_shader(self, factor, a, b):
        n = self.node("ShaderNodeMixShader")
        self.set(n.inputs[0], factor)
        self.tree.links.new(a, n.inputs[1])
        self.tree.links.new(b, n.inputs[2])
        return n.outputs[0]

    def translucent(self, color):
        n = self.node("ShaderNodeBsdfTranslucent")
        self.set(n.inputs["Color"], color)
        return n.outputs[0]

    def output(self, shader, kind: str = "ShaderNodeOutputMaterial") -> None:
        n = self.node(kind)
        self.tree.links.new(shader, n.inputs[0])
