"""Utility vehicles: trailers, box vans and a tracked excavator.

Local frame: +x forward (drawbar / cab / boom toward +x), z up, origin on the ground under the
centre of the footprint. Classes follow the datasets' definitions (see ``classes.yaml``):

* ``trailer``: a free-standing or car-towed trailer -> ``other_vehicle`` (SemanticKITTI
  other-vehicle, Cityscapes trailer). A trailer hitched to a truck would be ``truck``.
* ``box_van``: a van chassis with a separate box body (a Luton van) -> ``truck``: both
  SemanticKITTI ("vans with a body separate from the driver cabin") and Cityscapes ("box
  trucks ... loading area physically separated") call it a truck.
* ``construction_vehicle``: a tracked excavator -> ``other_vehicle`` (SemanticKITTI's fallback
  for vehicles it does not name; Cityscapes has no such class, see ``classes.yaml``).
"""

from __future__ import annotations

import numpy as np

from assets_procedural.parts import centred, sweep, wheel_cylinder
from assets_procedural.vehicle import _inset_quad
from generator.geometry import Mesh, box, cylinder, merge, polygon, pose, prism

GLASS = 0.02


def _finish(parts: list[Mesh], anchors: dict[str, np.ndarray] | None = None) -> Mesh:
    """Merge, attach ``anchors``, move the footprint centre to x = y = 0 and the lowest point to z = 0."""
    out = merge(parts)
    out.anchors = dict(anchors or {})
    return centred(out)


def _xz_prism(profile: np.ndarray, width: float, cls: str, material: str) -> Mesh:
    """Extrude a simple (x, z) profile (either winding) across y from -width/2 to +width/2."""
    prof = np.asarray(profile, float)
    area = np.sum(prof[:, 0] * np.roll(prof[:, 1], -1) - np.roll(prof[:, 0], -1) * prof[:, 1])
    if area < 0:
        prof = prof[::-1]
    # prism extrudes along z; roll +90 deg maps (px, py, pz) -> (x, y, z) = (px, -pz, py)
    return prism(prof, -width / 2, width / 2, cls, material, bottom=True).transformed(pose(roll=np.pi / 2))


# -- trailer ------------------------------------------------------------------------------------------

def trailer(rng: np.random.Generator, style: str | None = None) -> Mesh:
    """A single-axle car trailer parked on its jockey wheel: open box or closed box body.

    Parameters
    ----------
    style : {"open", "box"}, optional
        Low galvanised side walls or a closed box; drawn when omitted.

    Returns
    -------
    Mesh
        Class ``other_vehicle``; 2.6-4.3 m long (drawbar included), 1.5-2.1 m wide, 0.8-1.3 m
        (open) or 1.9-2.4 m (box) high; anchor ``"taillight"`` (2, 3).
    """
    style = str(rng.choice(["open", "box"])) if style is None else style
    if style not in ("open", "box"):
        raise ValueError(f"trailer style must be 'open' or 'box', got {style!r}")
    cls = "other_vehicle"
    bl, bw = float(rng.uniform(1.9, 3.0)), float(rng.uniform(1.2, 1.6))
    r = float(rng.uniform(0.26, 0.31))
    deck = r + float(rng.uniform(0.18, 0.25))
    draw = float(rng.uniform(0.9, 1.2))
    parts: list[Mesh] = [box((bl, bw, 0.04), cls, "fence_metal", (0.0, 0.0, deck + 0.02))]
    # chassis rails under the deck, drawbar V to the coupling, jockey wheel
    for s in (1.0, -1.0):
        parts.append(box((bl, 0.06, 0.1), cls, "pole_metal", (0.0, s * bw * 0.3, deck - 0.05)))
        parts.append(sweep(np.array([[bl / 2 - 0.2, s * bw * 0.3, deck - 0.05],
                                     [bl / 2 + draw - 0.25, s * 0.04, deck - 0.05]]),
                           0.035, cls, "pole_metal", 6))
    hitch = np.array([bl / 2 + draw, 0.0, deck - 0.05])
    parts.append(box((0.3, 0.1, 0.09), cls, "chrome", tuple(hitch - [0.12, 0.0, 0.0])))
    jx = bl / 2 + draw - 0.45
    parts.append(cylinder(0.03, deck - 0.05 - 0.1, cls, "pole_metal", 8, z0=0.1).transformed(pose(jx, 0.08)))
    parts.append(wheel_cylinder(jx, 0.08, 0.1, 0.06, cls, sections=10, hub="pole_metal"))
    if style == "open":
        wall = float(rng.uniform(0.3, 0.45))
        for s in (1.0, -1.0):
            parts.append(box((bl, 0.03, wall), cls, "fence_metal", (0.0, s * (bw / 2 - 0.015), deck + 0.04 + wall / 2)))
        for sx in (1.0, -1.0):
            parts.append(
                box((0.03, bw - 0.06, wall), cls, "fence_metal", (sx * (bl / 2 - 0.015), 0.0, deck + 0.04 + wall / 2))
            )
    else:
        hb = float(rng.uniform(1.3, 1.6))
        parts.append(box((bl, bw, hb), cls, "truck_paint", (0.0, 0.0, deck + 0.04 + hb / 2)))
        parts.append(box((0.02, bw - 0.2, hb - 0.15), cls, "pole_metal", (-bl / 2 - 0.01, 0.0, deck + 0.04 + hb / 2)))
    # axle: wheels outside the box under mudguards
    yw = bw / 2 + 0.1
    for s in (1.0, -1.0):
        parts.append(wheel_cylinder(0.0, s * yw, r, 0.17, cls, sections=14))
        ang = np.linspace(np.radians(160), np.radians(20), 7)
        guard = np.stack([(r + 0.07) * np.cos(ang), np.full(7, s * yw), r + (r + 0.07) * np.sin(ang)], 1)
        guard[:, 2] = np.maximum(guard[:, 2], deck - 0.02)
        parts.append(sweep(guard, (0.004, 0.11), cls, "fence_metal", 6, binormal=(0, 1, 0)))
    tail = np.array([[-bl / 2 - 0.03, s * (bw / 2 - 0.15), deck - 0.05] for s in (1.0, -1.0)])
    for c in tail:
        parts.append(box((0.04, 0.18, 0.08), cls, "taillight", tuple(c + [0.015, 0.0, 0.0])))
    return _finish(parts, {"taillight": tail})


# -- box van ------------------------------------------------------------------------------------------

def box_van(rng: np.random.Generator, luton: bool | None = None) -> Mesh:
    """A 3.5 t van with a separate box body (class ``truck``, see the module notes).

    Parameters
    ----------
    luton : bool, optional
        The box reaches forward over the cab roof (Luton peak); drawn when omitted.

    Returns
    -------
    Mesh
        Class ``truck``; 6.0-7.2 m long, 2.1-2.45 m wide (mirrors), 3.0-3.45 m high; dual rear
        wheels; anchors ``"headlight"`` and ``"taillight"`` (2, 3).
    """
    luton = bool(rng.random() < 0.5) if luton is None else bool(luton)
    cls = "truck"
    L, W, H = float(rng.uniform(6.0, 7.1)), float(rng.uniform(2.1, 2.25)), float(rng.uniform(3.0, 3.4))
    r = float(rng.uniform(0.35, 0.38))
    cab_l, cab_h = float(rng.uniform(1.9, 2.2)), float(rng.uniform(2.2, 2.45))
    cab_w = W - 0.12
    xfront = L / 2
    xback = xfront - cab_l
    xf, xr = xfront - float(rng.uniform(0.85, 0.95)), -L / 2 + float(rng.uniform(1.4, 1.8))
    hood_z, zb = 1.05, 0.38
    arch = [(xf + 1.1 * r * np.cos(t), r + 0.02 + 1.1 * r * np.sin(t)) for t in np.radians(np.arange(180, -1, -30))]
    prof = [(xback, zb), *arch, (xfront, zb), (xfront, hood_z - 0.1), (xfront - 0.55, hood_z),
            (xfront - 1.05, cab_h - 0.05), (xfront - 1.2, cab_h), (xback, cab_h)]
    parts: list[Mesh] = [_xz_prism(np.array(prof), cab_w, cls, "truck_paint")]
    floor = float(rng.uniform(0.85, 0.95))
    bx0 = xback - 0.05
    box_front = xback + (0.75 if luton else -0.0)
    parts.append(box((box_front + L / 2 - 0.02, W, H - floor), cls, "truck_paint",
                     ((box_front - L / 2 + 0.02) / 2, 0.0, (H + floor) / 2)))
    parts.append(box((bx0 + L / 2 - 0.2, 0.9, 0.25), cls, "rubber", ((bx0 - L / 2 + 0.2) / 2, 0.0, floor - 0.125)))
    parts.append(box((0.12, W - 0.2, 0.15), cls, "rubber", (-L / 2 + 0.25, 0.0, floor - 0.3)))
    parts.append(box((0.14, cab_w + 0.02, 0.22), cls, "rubber", (xfront - 0.05, 0.0, zb + 0.08)))
    # windscreen on the raked part, side windows
    ws = np.array([[xfront - 0.55, -cab_w / 2, hood_z], [xfront - 0.55, cab_w / 2, hood_z],
                   [xfront - 1.05, cab_w / 2, cab_h - 0.05], [xfront - 1.05, -cab_w / 2, cab_h - 0.05]])
    parts.append(_inset_quad(ws, 0.08, 0.05, np.array([cab_h - 0.05 - hood_z, 0.0, 0.5]), cls))
    for s in (1.0, -1.0):
        y = s * (cab_w / 2 + GLASS)
        q = np.array([[xback + 0.35, y, hood_z + 0.05], [xfront - 0.75, y, hood_z + 0.05],
                      [xfront - 1.12, y, cab_h - 0.12], [xback + 0.35, y, cab_h - 0.12]])
        parts.append(polygon(q, cls, "car_glass", (0, s, 0)))
        parts.append(box((0.06, 0.1, 0.3), cls, "tl_housing", (xfront - 0.6, s * (cab_w / 2 + 0.12), hood_z + 0.25)))
        parts.append(box((0.05, 0.1, 0.03), cls, "pole_metal", (xfront - 0.6, s * (cab_w / 2 + 0.05), hood_z + 0.25)))
        parts.append(wheel_cylinder(xf, s * (W / 2 - 0.14), r, 0.22, cls))
        parts.append(wheel_cylinder(xr, s * (W / 2 - 0.14), r, 0.22, cls))
        parts.append(wheel_cylinder(xr, s * (W / 2 - 0.38), r, 0.22, cls, hub="rubber"))
    head = np.array([[xfront + 0.02, s * (cab_w / 2 - 0.25), hood_z - 0.2] for s in (1.0, -1.0)])
    tail = np.array([[-L / 2 - 0.02, s * (W / 2 - 0.2), floor - 0.28] for s in (1.0, -1.0)])
    for c in head:
        parts.append(box((0.05, 0.28, 0.12), cls, "headlight", tuple(c - [0.025, 0, 0])))
    for c in tail:
        parts.append(box((0.05, 0.2, 0.12), cls, "taillight", tuple(c + [0.025, 0, 0])))
    parts.append(box((0.02, W - 0.25, H - floor - 0.25), cls, "pole_metal", (-L / 2 + 0.01, 0.0, (H + floor) / 2)))
    return _finish(parts, {"headlight": head, "taillight": tail})


# -- excavator ----------------------------------------------------------------------------------------

def construction_vehicle(rng: np.random.Generator, slew_deg: float | None = None, boom: str | None = None) -> Mesh:
    """A tracked hydraulic excavator: tracks, undercarriage, slewing house with cab and
    counterweight, two-piece boom, stick, bucket and chrome rams.

    Parameters
    ----------
    slew_deg : float, optional
        Yaw of the house and arm over the tracks, degrees (0: arm over the track front, +x);
        drawn from [-30, 30] when omitted.
    boom : {"raised", "lowered"}, optional
        Bucket high in the air or resting on the ground ahead; drawn when omitted.

    Returns
    -------
    Mesh
        Class ``other_vehicle``; tracks 3.6-4.2 m x 2.5-2.8 m, 2.9-5.5 m high.
    """
    slew = float(rng.uniform(-30, 30)) if slew_deg is None else float(slew_deg)
    boom = str(rng.choice(["raised", "lowered"])) if boom is None else boom
    if boom not in ("raised", "lowered"):
        raise ValueError(f"construction_vehicle boom must be 'raised' or 'lowered', got {boom!r}")
    cls = "other_vehicle"
    tl, tw, gauge = float(rng.uniform(3.6, 4.2)), float(rng.uniform(0.5, 0.6)), float(rng.uniform(2.0, 2.2))
    th = 0.75
    parts: list[Mesh] = []
    # tracks: stadium profile in x-z extruded across y; rollers as chrome-free dark discs
    a = np.linspace(-np.pi / 2, np.pi / 2, 7)
    rt = th / 2
    front = [(tl / 2 - rt + rt * np.cos(t), rt + rt * np.sin(t)) for t in a]
    back = [(-tl / 2 + rt - rt * np.cos(t), rt - rt * np.sin(t)) for t in a]
    prof = np.array(front + back)
    for s in (1.0, -1.0):
        parts.append(_xz_prism(prof, tw, cls, "rubber").transformed(pose(y=s * gauge / 2)))
        parts.append(
            box((tl - 2 * rt, 0.06, 0.3), cls, "truck_paint", (0.0, s * (gauge / 2 + tw / 2 + 0.01), rt + 0.05))
        )
    parts.append(box((tl * 0.55, gauge - tw, 0.4), cls, "truck_paint", (0.0, 0.0, th - 0.1)))
    parts.append(cylinder(0.55, 0.25, cls, "pole_metal", 16, z0=th + 0.05))
    # house (in its own frame, yawed by the slew): body, counterweight, cab, engine hood, arm
    hz = th + 0.3
    hl, hw_, hh = float(rng.uniform(2.8, 3.2)), float(rng.uniform(2.4, 2.6)), 1.0
    house: list[Mesh] = [box((hl, hw_, hh), cls, "truck_paint", (-0.25, 0.0, hz + hh / 2))]
    cw = [(-0.25 - hl / 2 + 0.05, hz), (-0.25 - hl / 2 - 0.25, hz + 0.15), (-0.25 - hl / 2 - 0.3, hz + hh - 0.1),
          (-0.25 - hl / 2 + 0.05, hz + hh + 0.05)]
    house.append(_xz_prism(np.array(cw), hw_, cls, "truck_paint"))
    house.append(box((1.2, hw_ - 0.3, 0.35), cls, "truck_paint", (-0.25 - hl / 2 + 0.7, 0.0, hz + hh + 0.17)))
    cab_x0, cab_x1, cab_y0, cab_y1 = 0.0, 1.25, 0.15, 1.15
    cab_h = float(rng.uniform(1.65, 1.8))
    zc0 = hz + hh
    house.append(box((cab_x1 - cab_x0, cab_y1 - cab_y0, cab_h), cls, "truck_paint",
                     ((cab_x0 + cab_x1) / 2, (cab_y0 + cab_y1) / 2, zc0 + cab_h / 2)))
    gz0, gz1 = zc0 + 0.15, zc0 + cab_h - 0.1
    house.append(polygon(np.array([[cab_x1 + GLASS, cab_y0 + 0.08, gz0], [cab_x1 + GLASS, cab_y1 - 0.08, gz0],
                                   [cab_x1 + GLASS, cab_y1 - 0.08, gz1], [cab_x1 + GLASS, cab_y0 + 0.08, gz1]]), cls,
                         "car_glass", (1, 0, 0)))
    for y, sgn in ((cab_y1 + GLASS, 1.0), (cab_y0 - GLASS, -1.0)):
        house.append(polygon(np.array([[cab_x0 + 0.1, y, gz0 + 0.3], [cab_x1 - 0.1, y, gz0 + 0.3],
                                       [cab_x1 - 0.1, y, gz1], [cab_x0 + 0.1, y, gz1]]), cls, "car_glass", (0, sgn, 0)))
    # boom foot right of the cab; boom (two straight pieces with an elbow), stick, bucket
    foot = np.array([hl / 2 - 0.4, -0.35, hz + 0.55])
    if boom == "raised":
        elbow = foot + np.array([1.8, 0.0, 2.3])
        tip = elbow + np.array([1.4, 0.0, 0.3])
        wrist = tip + np.array([0.6, 0.0, -2.2])
    else:   # bucket resting on the ground ahead
        elbow = foot + np.array([2.0, 0.0, 1.5])
        tip = elbow + np.array([2.0, 0.0, -0.5])
        wrist = np.array([tip[0] + 0.3, 0.0, 0.0])
    section = (0.22, 0.14)
    house.append(sweep(np.array([foot, elbow, tip]), section, cls, "truck_paint", 4, binormal=(0, 1, 0)))
    house.append(
        sweep(np.array([tip + [0.15, 0, 0.15], wrist]), (0.16, 0.12), cls, "truck_paint", 4, binormal=(0, 1, 0))
    )
    for p0, p1 in ((foot + [0.3, 0.0, -0.35], foot + 0.6 * (elbow - foot) + [0.0, 0.0, -0.15]),
                   (elbow + [0.1, 0.0, 0.25], tip + [0.1, 0.0, 0.35])):
        house.append(sweep(np.array([p0, p1]), 0.07, cls, "chrome", 6))
    # bucket: a C-shaped profile across y at the wrist, teeth down/forward
    bw = float(rng.uniform(0.8, 1.1))
    bucket = np.array(
        [(0.0, 0.0), (0.55, -0.45), (0.75, -0.9), (0.55, -0.95), (0.1, -0.75), (-0.25, -0.3), (-0.2, 0.05)]
    )
    if boom == "lowered":
        bucket = bucket @ np.array([[np.cos(0.6), -np.sin(0.6)], [np.sin(0.6), np.cos(0.6)]]).T
        wrist[2] = -bucket[:, 1].min() + 0.01
    bk = _xz_prism(bucket, bw, cls, "pole_metal").transformed(pose(wrist[0], foot[1], wrist[2]))
    house.append(bk)
    parts.append(merge(house).transformed(pose(yaw=np.radians(slew))))
    return _finish(parts)
