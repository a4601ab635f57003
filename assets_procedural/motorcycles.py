"""Motorcycles and scooters, parked (upright or on the side stand) or under a rider.

Local frame: +x forward, z up, origin on the ground at the centre of the footprint; both tyres
touch z = 0. Every face is class ``motorcycle``: cast wheels with a few thick spokes (open
between them) and a brake disc, fork, bars with grips and mirrors, tank, seat, engine,
exhaust; a fairing and screen on sport bikes; leg shield and floorboard on scooters. Riders:
:mod:`assets_procedural.riders`.
"""

from __future__ import annotations

import numpy as np

from assets_procedural.parts import centred, disc_wheel, oriented_box, sweep
from assets_procedural.two_wheelers import _style_params, _xz, contact_anchors
from generator.geometry import Mesh, box, loft, merge, polygon, pose, tube

MOTO_STYLES = ("naked", "sport", "scooter")

MOTO = {
    "naked": dict(R=(0.30, 0.315), tyre=(0.055, 0.062), wb=(1.38, 1.48), seat=(0.78, 0.84), bar=(0.74, 0.82),
                  rake=25.0),
    "sport": dict(R=(0.30, 0.315), tyre=(0.058, 0.065), wb=(1.38, 1.44), seat=(0.80, 0.85), bar=(0.64, 0.70),
                  rake=24.0),
    "scooter": dict(R=(0.22, 0.25), tyre=(0.045, 0.05), wb=(1.28, 1.36), seat=(0.76, 0.80), bar=(0.66, 0.72),
                    rake=27.0),
}


def _motorcycle_parts(rng: np.random.Generator, style: str | None) -> tuple[list[Mesh], dict]:
    """Motorcycle meshes in a raw frame (rear axle at x = 0, tyres on z = 0) and its contact points."""
    style, p = _style_params(rng, style, MOTO, "motorcycle")
    cls = "motorcycle"
    R, wb, tyre = p["R"], p["wb"], p["tyre"]
    ra, fa = np.array([0.0, 0.0, R]), np.array([wb, 0.0, R])
    y = np.array([0.0, 1.0, 0.0])
    parts: list[Mesh] = []
    spokes = int(rng.choice([3, 5, 6])) if style != "scooter" else 5
    parts.append(disc_wheel(ra, R, tyre, cls, spokes=spokes, width=2.4 * tyre))
    parts.append(disc_wheel(fa, R, tyre * 0.9, cls, spokes=spokes, width=2.0 * tyre))
    axis = _xz(90.0 - p["rake"])                              # steering axis, up and back
    head = fa + 0.04 * np.array([1.0, 0.0, 0.0]) + (0.72 if style != "scooter" else 0.78) * axis
    seat_z, seat_x = p["seat"], (0.3 if style == "scooter" else 0.42) * wb
    # front fork (two legs) and triple clamp
    for s in (1.0, -1.0):
        parts.append(tube(fa + s * 0.085 * y, head + s * 0.085 * y - 0.05 * axis, 0.028, cls,
                          "chrome" if style != "scooter" else "pole_metal", sections=6))
    parts.append(box((0.1, 0.24, 0.05), cls, "pole_metal", tuple(head - 0.02 * axis)))
    # handlebar, grips, mirrors
    half = p["bar"] / 2
    bar_c = head + np.array([-0.06, 0.0, 0.10 if style != "sport" else 0.02])
    grips = []                                               # right (-y) first, then left
    for s in (-1.0, 1.0):
        end = bar_c + np.array([-0.1 if style != "sport" else -0.02, s * half, 0.04 if style == "naked" else 0.0])
        parts.append(sweep(np.array([bar_c, bar_c + [0.0, s * 0.12, 0.0], end]), 0.012, cls, "pole_metal", 6))
        inward = (bar_c + [0.0, s * 0.12, 0.0] - end) / np.linalg.norm(bar_c + [0.0, s * 0.12, 0.0] - end)
        parts.append(tube(end - 0.005 * inward, end + 0.13 * inward, 0.02, cls, "rubber", sections=6))
        grips.append(end + 0.06 * inward)
        stalk = end + 0.16 * inward
        parts.append(tube(stalk, stalk + np.array([0.02, s * 0.06, 0.22]), 0.006, cls, "pole_metal", sections=4))
        parts.append(box((0.02, 0.12, 0.07), cls, "chrome", tuple(stalk + np.array([0.02, s * 0.08, 0.25]))))
    parts.append(tube(head - 0.02 * axis, bar_c, 0.02, cls, "pole_metal", sections=6))
    if style == "scooter":
        floor_z = 0.30
        # leg shield, floorboard, rear body over the engine, seat; room for the legs between them
        front = np.array([seat_x + 0.62, seat_x + 0.82])
        ring = lambda x, w, z0, z1: np.array([[x, -w, z0], [x, w, z0], [x, w, z1], [x, -w, z1]])  # noqa: E731
        parts.append(loft(np.array([ring(front[0], 0.2, floor_z - 0.02, head[2] - 0.1),
                                    ring(front[1], 0.17, floor_z + 0.05, head[2] - 0.02)]), cls, "car_paint"))
        parts.append(box((front[0] - seat_x, 0.34, 0.06), cls, "rubber", ((front[0] + seat_x) / 2, 0.0, floor_z)))
        body = []
        for x, w, z0, z1 in (
            (seat_x + 0.16, 0.15, floor_z + 0.03, seat_z - 0.1),
            (seat_x, 0.19, R + 0.08, seat_z - 0.06),
            (-0.2, 0.16, R + 0.12, seat_z - 0.1),
            (-0.42, 0.08, R + 0.2, seat_z - 0.2),
        ):
            body.append(ring(x, w, z0, z1))
        parts.append(loft(np.array(body), cls, "car_paint"))
        parts.append(loft(np.array([ring(seat_x + 0.18, 0.13, seat_z - 0.1, seat_z - 0.02),
                                    ring(seat_x, 0.17, seat_z - 0.1, seat_z),
                                    ring(-0.3, 0.12, seat_z - 0.1, seat_z - 0.03)]),
                          cls, "rubber"))
        parts.append(box((0.25, 0.14, 0.1), cls, "pole_metal", (0.1, -0.12, R + 0.02)))
        parts.append(tube(np.array([0.15, -0.12, 0.2]), np.array([-0.3, -0.15, 0.25]), 0.04, cls, "chrome", sections=6))
        feet = [np.array([seat_x + 0.45, s * 0.12, floor_z + 0.03]) for s in (-1.0, 1.0)]
        light_f = np.array([front[0] + 0.22, 0.0, head[2] - 0.1])
        light_r = np.array([-0.44, 0.0, seat_z - 0.16])
    else:
        # frame spine, tank, seat, tail; engine block, swingarm, exhaust, radiator
        tank = []
        tx = np.linspace(head[0] - 0.08, seat_x + 0.18, 5)
        for k, x in enumerate(tx):
            w = [0.10, 0.16, 0.19, 0.17, 0.12][k]
            z0, z1 = seat_z - 0.2, [head[2] + 0.02, seat_z + 0.2, seat_z + 0.18, seat_z + 0.12, seat_z + 0.02][k]
            a = np.linspace(0, 2 * np.pi, 10, endpoint=False)
            tank.append(np.stack([np.full(10, x), w * np.cos(a), (z0 + z1) / 2 + (z1 - z0) / 2 * np.sin(a)], 1))
        parts.append(loft(np.array(tank), cls, "car_paint"))
        seat = []
        for x, w, zt in (
            (seat_x + 0.2, 0.12, seat_z - 0.01),
            (seat_x, 0.15, seat_z),
            (seat_x - 0.3, 0.13, seat_z + 0.03),
            (seat_x - 0.5, 0.09, seat_z + 0.06),
        ):
            a = np.linspace(0, 2 * np.pi, 8, endpoint=False)
            seat.append(np.stack([np.full(8, x), w * np.cos(a), zt - 0.05 + 0.05 * np.sin(a)], 1))
        parts.append(loft(np.array(seat), cls, "rubber"))
        tail = []
        for x, w, z0, z1 in (
            (seat_x - 0.3, 0.12, seat_z - 0.2, seat_z - 0.02),
            (seat_x - 0.55, 0.09, seat_z - 0.1, seat_z + 0.03),
            (seat_x - 0.75, 0.05, seat_z - 0.02, seat_z + 0.05),
        ):
            a = np.linspace(0, 2 * np.pi, 8, endpoint=False)
            tail.append(np.stack([np.full(8, x), w * np.cos(a), (z0 + z1) / 2 + (z1 - z0) / 2 * np.sin(a)], 1))
        parts.append(loft(np.array(tail), cls, "car_paint"))
        eng_c = np.array([0.55 * wb, 0.0, R + 0.07])
        parts.append(box((0.42, 0.3, 0.36), cls, "pole_metal", tuple(eng_c)))
        parts.append(oriented_box(eng_c + np.array([0.12, 0.0, 0.26]), (0.16, 0.26, 0.22), cls, "chrome", pitch=-0.3))
        for s in (1.0, -1.0):
            parts.append(
                tube(ra + s * 0.08 * y, eng_c + np.array([-0.2, s * 0.09, 0.0]), 0.03, cls, "pole_metal", sections=6)
            )
            parts.append(
                tube(
                    head + s * 0.05 * y, eng_c + np.array([-0.15, s * 0.1, 0.15]), 0.025, cls, "pole_metal", sections=6
                )
            )
        parts.append(tube(np.array([0.12, 0.0, R + 0.12]), np.array([seat_x - 0.05, 0.0, seat_z - 0.12]), 0.03, cls,
                          "chrome", sections=6))
        parts.append(sweep(np.array([eng_c + [0.15, -0.1, -0.15], eng_c + [-0.05, -0.17, -0.22], [0.2, -0.2, R - 0.08],
                                     [-0.25, -0.2, R + 0.12]]), 0.045, cls, "chrome", 8))
        parts.append(sweep(np.array([fa + [-0.2, 0, 0.18], fa + [0.0, 0, R - 0.03], fa + [0.18, 0, R - 0.12]]),
                           (0.008, 0.07), cls, "car_paint", 6, binormal=(0, 1, 0)))
        feet = [np.array([seat_x + 0.12, s * (0.2 if style == "naked" else 0.23), R + 0.06]) for s in (-1.0, 1.0)]
        for f in feet:
            parts.append(tube(f - [0, np.sign(f[1]) * 0.1, 0], f + [0, np.sign(f[1]) * 0.04, 0], 0.012, cls,
                              "pole_metal", sections=6))
        light_f = head + np.array([0.14, 0.0, -0.08])
        light_r = np.array([seat_x - 0.78, 0.0, seat_z + 0.0])
        if style == "sport":
            fair = []
            for x, w, z0, z1 in ((head[0] + 0.2, 0.08, head[2] - 0.2, head[2] + 0.08),
                                 (head[0] + 0.05, 0.2, R + 0.05, head[2] + 0.12),
                                 (head[0] - 0.25, 0.23, R - 0.02, head[2] + 0.0),
                                 (eng_c[0] - 0.15, 0.16, R - 0.05, seat_z - 0.15)):
                a = np.linspace(0, 2 * np.pi, 10, endpoint=False)
                fair.append(np.stack([np.full(10, x), w * np.cos(a), (z0 + z1) / 2 + (z1 - z0) / 2 * np.sin(a)], 1))
            parts.append(loft(np.array(fair), cls, "car_paint"))
            ws = np.array([[head[0] + 0.06, -0.13, head[2] + 0.1], [head[0] + 0.06, 0.13, head[2] + 0.1],
                           [head[0] - 0.1, 0.1, head[2] + 0.3], [head[0] - 0.1, -0.1, head[2] + 0.3]])
            parts.append(polygon(ws, cls, "car_glass", (0.8, 0.0, 0.6)))
            light_f = np.array([head[0] + 0.22, 0.0, head[2] - 0.05])
    parts.append(box((0.05, 0.16, 0.09), cls, "headlight", tuple(light_f)))
    parts.append(box((0.04, 0.12, 0.05), cls, "taillight", tuple(light_r)))
    parts.append(sweep(np.array([ra + [0.1, 0, R + 0.03], ra + [-0.1, 0, R + 0.04], ra + [-0.3, 0, R - 0.05]]),
                       (0.006, 0.09), cls, "car_paint", 6, binormal=(0, 1, 0)))
    info = dict(style=style, R=R, saddle=np.array([seat_x, 0.0, seat_z]), grips=grips, feet=feet,
                headlight=light_f + [0.03, 0, 0], taillight=light_r - [0.025, 0, 0])
    return parts, info


def motorcycle(rng: np.random.Generator, style: str | None = None, lean_deg: float = 0.0) -> Mesh:
    """A motorcycle or scooter (no rider).

    Parameters
    ----------
    style : {"naked", "sport", "scooter"}, optional
        Standard bike with round lamp and exposed engine; sport bike with fairing and screen;
        step-through scooter with small wheels, leg shield and floorboard. Drawn when omitted.
    lean_deg : float
        Roll (a bike on its side stand leans ~10 degrees to the left, +).

    Returns
    -------
    Mesh
        Class ``motorcycle``: 1.7-2.3 m long, 0.65-1.0 m wide (bars, mirrors), 1.05-1.45 m
        high; anchors ``"headlight"`` (1, 3) and ``"taillight"`` (1, 3).
    """
    parts, info = _motorcycle_parts(rng, style)
    m = merge(parts)
    m.anchors = {"headlight": info["headlight"][None], "taillight": info["taillight"][None], **contact_anchors(info)}
    if lean_deg:
        m = m.transformed(pose(roll=np.radians(lean_deg)))
    return centred(m)
