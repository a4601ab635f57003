"""A car body's panel gaps and door handles, drawn by its paint from the mesh's seam properties.

The car's shell is one lofted surface (:mod:`assets_procedural.car_body`); its builder marks where the
panels of a real car meet as anchors (:mod:`assets_procedural.car_seams`: ``seam/doors``, ``seam/band``,
``seam/handles``, ``seam/bumpers``, ``seam/lids``). :func:`seam_properties` packs them into four-float
custom properties of the Blender mesh (:func:`generator.blender.geometry.mesh` sets them), which a shader's
``OBJECT`` attribute reads from the object's mesh; :func:`seam_gaps` turns them into a gap mask (4 mm dark
lines: the doors' three vertical seams between sill and belt, the bumpers' top edges from the wheel arches
round the corners, the bonnet's front edge and sides, the boot lid's or tailgate's) and a door-handle mask.
Only the paint changes: the triangles the camera and the LiDAR see and the label passes stay as they were.
A mesh without the properties (every other body) reads zeros: ``ug_seam_on`` 0 draws nothing.
"""

from __future__ import annotations

from generator.blender.nodes import Nodes

GAP_M = 0.004        #: width of a panel gap, metres (3-5 mm on production cars)
HANDLE_M = (0.17, 0.032)  #: door handle length and height, metres (:mod:`assets_procedural.car_seams`)
_KEYS = ("seam/doors", "seam/band", "seam/handles", "seam/bumpers", "seam/lids")


def seam_properties(anchors: dict) -> dict[str, tuple[float, ...]]:
    """The mesh properties :func:`seam_gaps` reads, from a car mesh's seam anchors (on the ground).

    Parameters
    ----------
    anchors : dict of str to (k, 3) float
        A prototype mesh's anchors (car frame, metres).

    Returns
    -------
    dict of str to tuple of floats
        ``ug_seam_on`` (1.0,); ``ug_seam_doors`` (x front, x middle, x rear, z sill); ``ug_seam_band`` (z belt,
        z handles, x front handle, x rear handle); ``ug_seam_ends`` (x and z of the front bumper's edge, x and
        z of the rear's); ``ug_seam_lids`` (bonnet x, bonnet sides |y|, boot x, boot sides |y|); ``ug_seam_lamp``
        (x, |y|, z of the headlamp's centre, 1). Empty when the anchors hold no seams (not a car body).
    """
    if not all(k in anchors for k in _KEYS):
        return {}
    doors, band, handles = anchors["seam/doors"], anchors["seam/band"], anchors["seam/handles"]
    ends, lids = anchors["seam/bumpers"], anchors["seam/lids"]
    props = {
        "ug_seam_on": (1.0,),
        "ug_seam_doors": (*doors[:, 0], band[0, 2]),
        "ug_seam_band": (band[1, 2], handles[0, 2], handles[0, 0], handles[1, 0]),
        "ug_seam_ends": (ends[0, 0], ends[0, 2], ends[1, 0], ends[1, 2]),
        "ug_seam_lids": (lids[0, 0], lids[0, 1], lids[1, 0], lids[1, 1]),
    }
    if "headlight" in anchors:                  # the left lamp's centre: |y| and z, the inner parts drawn round it
        head = anchors["headlight"][0]
        props["ug_seam_lamp"] = (head[0], abs(head[1]), head[2], 1.0)
    return {k: tuple(float(x) for x in v) for k, v in props.items()}


def _four(g: Nodes, name: str) -> list:
    """The four floats of the mesh property ``name`` as sockets."""
    sep = g.node("ShaderNodeSeparateXYZ")
    g.set(sep.inputs[0], g.attr(name, "OBJECT", "Vector"))
    return [sep.outputs["X"], sep.outputs["Y"], sep.outputs["Z"], g.attr(name, "OBJECT", "Alpha")]


def _near(g: Nodes, v, c, half: float):
    """1 within ``half`` metres of ``c``, falling to 0 over the next ``half`` (a line of width ~2*half)."""
    d = g.math("ABSOLUTE", g.math("SUBTRACT", v, c))
    return g.math("SUBTRACT", 1.0, g.smooth(d, half, 2.0 * half))


def _above(g: Nodes, v, c):
    return g.math("GREATER_THAN", v, c)


def _all(g: Nodes, *masks):
    out = masks[0]
    for m in masks[1:]:
        out = g.mul(out, m)
    return out


def seam_gaps(g: Nodes) -> tuple:
    """(gap, handle) masks in [0, 1] at the shading point of a car body (0 where ``ug_seam_on`` is 0).

    ``gap`` is 1 in a panel gap; ``handle`` 1 on a door handle's recess outline, 0.5 inside it.
    """
    co = g.node("ShaderNodeSeparateXYZ")
    g.set(co.inputs[0], g.coords("Object"))
    x, z = co.outputs["X"], co.outputs["Z"]
    ay = g.math("ABSOLUTE", co.outputs["Y"])
    up = g.node("ShaderNodeSeparateXYZ")
    g.set(up.inputs[0], g.geometry("Normal"))
    flat = _above(g, up.outputs["Z"], 0.6)               # a lid's top, not its face (cars stand level)
    x_front, x_mid, x_rear, sill = _four(g, "ug_seam_doors")
    belt, z_handle, xh_front, xh_rear = _four(g, "ug_seam_band")
    x_bf, z_bf, x_br, z_br = _four(g, "ug_seam_ends")
    x_hood, y_hood, x_boot, y_boot = _four(g, "ug_seam_lids")
    h = GAP_M / 2
    in_doors = _all(g, _above(g, z, sill), _above(g, belt, z))
    doors = g.math("MAXIMUM", g.math("MAXIMUM", _near(g, x, x_front, h), _near(g, x, x_mid, h)),
                   _near(g, x, x_rear, h))
    gaps = [_all(g, doors, in_doors),
            _all(g, _near(g, z, z_bf, h), _above(g, x, x_bf)),                     # front bumper's top edge
            _all(g, _near(g, z, z_br, h), _above(g, x_br, x)),                     # rear bumper's top edge
            _all(g, _near(g, x, x_hood, h), flat, _above(g, z, g.add(z_bf, 0.1))),  # bonnet's front edge
            _all(g, _near(g, ay, y_hood, h), _above(g, x, x_front), _above(g, z, g.add(z_bf, 0.1))),  # its sides
            _all(g, _near(g, x, x_boot, h), flat, _above(g, z, g.add(z_br, 0.1))),  # boot lid's front edge
            _all(g, _near(g, ay, y_boot, h), _above(g, g.add(x_boot, 0.03), x), _above(g, z, z_br))]  # its sides
    gap = gaps[0]
    for m in gaps[1:]:
        gap = g.math("MAXIMUM", gap, m)
    # door handles: a recess outline round a body-coloured grip, a hand's width ahead of each door's rear edge
    hx, hz = HANDLE_M[0] / 2, HANDLE_M[1] / 2
    near_front = g.math("MINIMUM", g.math("ABSOLUTE", g.math("SUBTRACT", x, xh_front)),
                        g.math("ABSOLUTE", g.math("SUBTRACT", x, xh_rear)))
    dz = g.math("ABSOLUTE", g.math("SUBTRACT", z, z_handle))
    outer = _all(g, _above(g, hx + 0.004, near_front), _above(g, hz + 0.004, dz))
    inner = _all(g, _above(g, hx, near_front), _above(g, hz, dz))
    handle = g.math("SUBTRACT", outer, g.mul(inner, 0.5))
    on = g.attr("ug_seam_on", "OBJECT", "Fac")
    return g.mul(gap, on), g.mul(handle, on)


GRILLE_PITCH_M = 0.022   #: slat pitch of the radiator grille, metres


def grille_slats(g: Nodes):
    """(grille, slat) masks at a car's trim: ``grille`` 1 on the black trim ahead of the front bumper's edge
    and above it (the grille, not the sills), ``slat`` 1 on a slat's face and 0 in the dark gap between slats
    (horizontal slats every :data:`GRILLE_PITCH_M`). Both 0 where ``ug_seam_on`` is 0."""
    co = g.node("ShaderNodeSeparateXYZ")
    g.set(co.inputs[0], g.coords("Object"))
    x, z = co.outputs["X"], co.outputs["Z"]
    x_bf, z_bf, _, _ = _four(g, "ug_seam_ends")
    grille = _all(g, _above(g, x, x_bf), _above(g, z, g.math("SUBTRACT", z_bf, 0.08)),
                  g.attr("ug_seam_on", "OBJECT", "Fac"))
    phase = g.math("FRACT", g.math("DIVIDE", z, GRILLE_PITCH_M))
    slat = g.math("SUBTRACT", 1.0, g.smooth(phase, 0.55, 0.7))
    return grille, slat


def headlamp_inside(g: Nodes):
    """(chrome, black, eye, on) masks behind a car's headlamp lens, in [0, 1], all 0 where ``ug_seam_lamp`` is
    missing (``on``: 1 on a car's lamp): two projectors side by side round the lamp's centre (a dark glass
    lens of 20 mm radius in a thin chrome rim), in a smoked housing (``black``)."""
    co = g.node("ShaderNodeSeparateXYZ")
    g.set(co.inputs[0], g.coords("Object"))
    ay, z = g.math("ABSOLUTE", co.outputs["Y"]), co.outputs["Z"]
    _, y_c, z_c, on = _four(g, "ug_seam_lamp")
    dv = g.math("SUBTRACT", z, z_c)
    eyes = []
    for du in (-0.035, 0.035):                  # two projectors either side of the centre
        dy = g.math("SUBTRACT", ay, g.add(y_c, du))
        r = g.math("SQRT", g.add(g.mul(dy, dy), g.mul(dv, dv)))
        eyes.append(r)
    r = g.math("MINIMUM", *eyes)
    eye = g.math("SUBTRACT", 1.0, g.smooth(r, 0.019, 0.022))         # the projector's dark glass lens
    rim = g.math("SUBTRACT", g.math("SUBTRACT", 1.0, g.smooth(r, 0.024, 0.027)), eye)   # its thin chrome rim
    low = g.math("LESS_THAN", dv, -0.022)                              # the housing's lower band
    chrome = g.mul(rim, g.math("SUBTRACT", 1.0, low))
    black = g.math("MAXIMUM", low, g.math("SUBTRACT", g.math("SUBTRACT", 1.0, rim), eye))   # smoked housing
    return g.mul(chrome, on), g.mul(black, on), g.mul(eye, on), on
