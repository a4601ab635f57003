"""Vehicles: cars (sedan, hatchback, estate, SUV, MPV van, pickup) and box trucks.

Local frame: +x forward (headlights at +x), z up, origin on the ground under the centre
of the bounding box. Cars are one class (``car``): a curved lofted shell whose greenhouse
faces are the glass (:mod:`assets_procedural.car_body`), wheels, lamps and plates. Trucks
likewise with class ``truck``; their glass sits 2 cm proud of the body surface so it never
z-fights with the paint.
"""

from __future__ import annotations

import numpy as np

from assets_procedural.car_body import body_shell, draw_dimensions
from assets_procedural.car_lamps import lamp
from assets_procedural.car_seams import seam_anchors
from assets_procedural.vehicle_interior import car_interior
from generator.geometry import Mesh, box, cylinder, disc, loft, merge, on_ground, polygon, pose, prism, resolve_ids
from generator.geometry.primitives import quads

GLASS_OFFSET = 0.02  # metres: glass in front of the body surface (>= 2 cm: no z-fighting)
PROUD_M = 0.025      #: how far a car's lamps and plates stand out of its nose and tail, metres

#: body types of :func:`car` and their share of a town's cars: compact (``hatchback``), saloon
#: (``sedan``), estate, SUV/crossover, MPV (``van``) and pickup. Assumed shares of the European car
#: *parc* (cars on the road, not new sales): SUVs were ~20 % of EU new registrations in 2014 and ~50 %
#: in 2023 (JATO Dynamics), and the parc averages ~12 years (ACEA, "Vehicles on European roads" 2023),
#: so SUVs and compacts lead at ~28 % each, saloons and estates follow; MPVs are a fading segment
#: (~8 %); pickups are ~1 % in Europe and more in North America -- kept at 6 % so that a library of
#: dozens holds a few. Dimensions per type: :data:`assets_procedural.car_body.BODY_TYPES` (ranges of
#: the best-selling models of each type), drawn uniformly within the range.
CAR_VARIANTS: dict[str, float] = {"sedan": 0.18, "hatchback": 0.28, "estate": 0.12, "suv": 0.28, "van": 0.08,
                                  "pickup": 0.06}


def wheel(x: float, y_out: float, side: float, radius: float, width: float, cls: str,
          sections: int = 12) -> Mesh:
    """A tyre (``rubber``) with a hub disc (``chrome``) on its outer face.

    ``sections`` should be a multiple of 4 so that a vertex touches the ground (z = 0).

    Parameters
    ----------
    x : float
        Axle position along x, metres.
    y_out : float
        |y| of the tyre's outer face, metres.
    side : float
        +1 for the left (+y) wheel, -1 for the right.
    """
    tyre = cylinder(radius, width, cls, "rubber", sections)          # axis z, z in [0, width]
    tyre = tyre.transformed(pose(x, side * y_out, radius, roll=side * np.pi / 2))
    hub = disc((x, side * (y_out + 0.01), radius), (0, side, 0), 0.62 * radius, cls, "chrome", 10)
    return merge([tyre, hub])


def _light(x: float, y: float, z: float, size: tuple[float, float, float], cls: str, material: str) -> Mesh:
    return box(size, cls, material, (x, y, z))


def _inset_quad(q: np.ndarray, du: float, dv: float, normal: np.ndarray, cls: str) -> Mesh:
    """A glass pane inside the quad ``q`` and ``GLASS_OFFSET`` in front of it.

    Parameters
    ----------
    q : (4, 3) float
        Corners [a0, a1, b1, b0]: a0 -> a1 across the pane, a -> b along it.
    du, dv : float
        Margins (metres) left across and along (the pillars and seals).
    normal : (3,) float
        Outward direction of the pane.
    """
    a0, a1, b1, b0 = q
    su = du / np.linalg.norm(a1 - a0)
    tv = dv / np.linalg.norm(b0 - a0)

    def at(s: float, t: float) -> np.ndarray:
        return (1 - t) * ((1 - s) * a0 + s * a1) + t * ((1 - s) * b0 + s * b1)

    n = normal / np.linalg.norm(normal)
    c = np.array([at(su, tv), at(1 - su, tv), at(1 - su, 1 - tv), at(su, 1 - tv)])
    return polygon(c + GLASS_OFFSET * n, cls, "car_glass", n)


def car_wheel(x: float, y_out: float, side: float, radius: float, width: float, cls: str = "car",
              sections: int = 12) -> Mesh:
    """A car wheel: a tyre with rounded shoulders (``rubber``), a rim face (``wheel_rim``) with five spokes
    between dark openings (``rubber``) and a hub cap.

    Parameters
    ----------
    x : float
        Axle position along x, metres; the axle is at z = ``radius`` (the tyre touches z = 0).
    y_out : float
        |y| of the tyre's outer face, metres.
    side : float
        +1 for the left (+y) wheel, -1 for the right.
    sections : int
        Points around; a multiple of 4, so one vertex touches the ground.
    """
    a = 2 * np.pi * np.arange(sections) / sections
    c, s = np.cos(a), np.sin(a)
    y_in = y_out - width
    profile = [(0.66 * radius, y_in), (radius, y_in + 0.03), (radius, y_out - 0.03), (0.66 * radius, y_out)]
    rings = np.array([np.stack([x + rr * c, np.full(sections, side * yy), radius + rr * s], 1) for rr, yy in profile])
    tyre = loft(rings, cls, "rubber")
    _, rim = resolve_ids(cls, "wheel_rim")
    tyre.face_material[-sections:] = rim                             # the outer cap: the rim face
    hub = disc((x, side * (y_out + 0.006), radius), (0, side, 0), 0.2 * radius, cls, "chrome", 6)
    return merge([tyre, hub, _rim_openings(x, side * (y_out + 0.003), radius, side, cls)])


def _rim_openings(x: float, y: float, radius: float, side: float, cls: str, spokes: int = 5) -> Mesh:
    """The dark openings between an alloy rim's ``spokes`` (``rubber``: the brake behind, dark), 3 mm proud
    of the rim face at ``y``: ``spokes`` quads that leave the spokes in the rim's metal between them."""
    period = 2 * np.pi / spokes
    mid = period * (np.arange(spokes) + 0.5)
    t0, t1 = mid - 0.3 * period, mid + 0.3 * period
    r0, r1 = 0.27 * radius, 0.58 * radius

    def at(r, t):
        return np.stack([x + r * np.cos(t), np.full_like(t, y), radius + r * np.sin(t)], -1)

    corners = np.stack([at(r0, t0), at(r1, t0), at(r1, t1), at(r0, t1)], 1)
    return quads(corners, cls, "rubber", np.tile([0.0, side, 0.0], (spokes, 1)))


def _arch_wall(x: float, y: float, side: float, r: float, arch: float, cls: str) -> Mesh:
    """The inner wall of a wheel house: closes the arch tunnel behind the tyre (``car_trim``)."""
    ang = np.radians(np.linspace(0, 180, 7))
    pts = [(x + arch * np.cos(t), side * y, r + arch * np.sin(t)) for t in ang]
    pts += [(x - arch, side * y, r - 0.05), (x + arch, side * y, r - 0.05)]
    return polygon(np.array(pts), cls, "car_trim", (0, side, 0))


def car(rng: np.random.Generator, variant: str | None = None, quantile: float | None = None) -> Mesh:
    """A passenger car: a lofted, curved body of one body type, with wheels, lights and plates.

    Parameters
    ----------
    rng : numpy.random.Generator
        Body type (when not given) and every dimension are drawn from it.
    variant : {"sedan", "hatchback", "estate", "suv", "van", "pickup"}, optional
        Body type (:data:`assets_procedural.car_body.BODY_TYPES`); drawn with the shares of
        :data:`CAR_VARIANTS` when omitted.
    quantile : float in [0, 1), optional
        Instead of ``variant``: the body type at this quantile of the cumulative shares of
        :data:`CAR_VARIANTS` (a library of ``n`` cars asks for ``(i + 0.5) / n`` and so holds every
        type in its share).

    Returns
    -------
    Mesh
        Class ``car``; 3.8-5.4 m long, 1.7-2.3 m wide (mirrors included), 1.4-1.85 m high, the
        four tyres the only faces at z = 0 and the body ``clear`` (0.13-0.24 m) above the ground.
        Materials ``car_body`` (the shell: colour per object, shaded smooth), ``car_paint`` (mirrors),
        ``car_glass``, ``car_trim``,
        ``rubber``, ``wheel_rim``, ``chrome``, ``headlight``, ``taillight``, ``licence_plate``.
        Anchors ``"headlight"`` (2, 3) and ``"taillight"`` (2, 3) on the lamp faces.
    """
    names = list(CAR_VARIANTS)
    if variant is None and quantile is not None:
        if not 0.0 <= quantile < 1.0:
            raise ValueError(f"car quantile must be in [0, 1), got {quantile}")
        cum = np.cumsum(list(CAR_VARIANTS.values()))
        variant = names[min(int(np.searchsorted(cum / cum[-1], quantile, side="right")), len(names) - 1)]
    if variant is None:
        variant = names[int(rng.choice(len(names), p=np.array(list(CAR_VARIANTS.values()))))]
    if variant not in CAR_VARIANTS:
        raise ValueError(f"car variant must be one of {names}, got {variant!r}")
    p = draw_dimensions(rng, variant)
    shell, info = body_shell(p, variant)
    L, W, r, tyre_w = p["L"], p["W"], p["r"], 0.2 + 0.1 * (p["r"] - 0.29)
    parts = [shell, car_interior(p, info)]
    for x in (info["xr"], info["xf"]):
        for side in (1.0, -1.0):
            parts.append(car_wheel(x, W / 2 - 0.025, side, r, tyre_w))
            parts.append(_arch_wall(x, W / 2 - 0.05 - tyre_w - 0.02, side, r, r + 0.055, "car"))
    xs, top, half = info["xs"], info["top"], info["half_w"]
    nose, tail_top = float(top[-1]), float(top[0])
    hw_end = float(half[-1])
    yl, yt = hw_end - 0.24, hw_end - 0.17
    head = np.array([[L / 2 + PROUD_M, s * yl, nose - 0.0625] for s in (1, -1)])
    tail = np.array([[-L / 2 - PROUD_M, s * yt, tail_top - 0.0975] for s in (1, -1)])
    parts.append(lamp(info, True, yl - 0.18, nose - 0.1, nose - 0.025, 0.2, "headlight"))    # lenses on the shell
    parts.append(lamp(info, False, yt - 0.12, tail_top - 0.15, tail_top - 0.045, 0.13, "taillight"))
    bottom_f, bottom_r = float(info["bottom"][-1]), float(info["bottom"][0])
    parts.append(box((0.08, 2 * yl - 0.42, 0.13), "car", "car_trim", (L / 2 - 0.035, 0, nose - 0.12)))  # grille
    parts.append(box((0.03, 0.52, 0.11), "car", "licence_plate", (L / 2 + PROUD_M - 0.015, 0, bottom_f + 0.1)))
    plate_z = max(bottom_r + 0.1, tail_top - 0.3)
    parts.append(box((0.03, 0.52, 0.11), "car", "licence_plate", (-L / 2 - PROUD_M + 0.015, 0, plate_z)))
    i_a = int(np.searchsorted(xs, info["xa"]))
    hw_a = float(half[min(i_a, len(half) - 1)])
    for side in (1.0, -1.0):
        parts.append(box((0.09, 0.12, 0.1), "car", "car_paint", (info["xa"], side * (hw_a + 0.02),
                                                                 p["belt_z"] + 0.09)))
    body = merge(parts)
    body.anchors = {"headlight": head, "taillight": tail, **seam_anchors(p, info)}  # seams: drawn by the paint
    return on_ground(body)


def truck(rng: np.random.Generator) -> Mesh:
    """A two-axle box truck (cab-over, cargo box, dual rear wheels).

    Returns
    -------
    Mesh
        Class ``truck``; 6.5-9.0 m long, 2.3-2.5 m wide (mirrors included), 3.0-3.8 m high;
        6 wheels; anchors ``"headlight"`` (2, 3) and ``"taillight"`` (2, 3).
    """
    L, W, H = rng.uniform(6.5, 8.97), rng.uniform(2.25, 2.34), rng.uniform(3.0, 3.8)  # lamps add 2 cm at the rear
    r = float(rng.uniform(0.45, 0.5))
    cab_l, cab_h = rng.uniform(1.75, 2.1), min(H - 0.15, rng.uniform(2.55, 2.9))
    xfront, xback = L / 2 - 0.05, L / 2 - 0.05 - cab_l
    xf, xr = L / 2 - rng.uniform(0.95, 1.1), -L / 2 + rng.uniform(1.5, 2.1)
    zb, zw = min(0.45, r), 1.3
    arch = [(xf + 1.12 * r * np.cos(t), r + 1.12 * r * np.sin(t)) for t in np.radians(np.arange(180, -1, -30))]
    prof = [(xback, zb), *arch, (xfront, zb), (xfront, zw), (xfront - 0.22, cab_h - 0.08),
            (xfront - 0.35, cab_h), (xback, cab_h)]
    # prism extrudes along z; roll +90 deg maps (px, py, pz) -> (x, y, z) = (px, -pz, py)
    cab = prism(np.array(prof), -W / 2, W / 2, "truck", "truck_paint", bottom=True).transformed(pose(roll=np.pi / 2))
    floor = float(rng.uniform(1.05, 1.2))
    x_box0 = xback - 0.12
    parts = [cab,
             box((x_box0 + L / 2, W, H - floor), "truck", "truck_paint", ((x_box0 - L / 2) / 2, 0, (H + floor) / 2)),
             box((x_box0 + L / 2 - 0.3, 0.9, 0.3), "truck", "rubber", ((x_box0 - L / 2 + 0.3) / 2, 0, floor - 0.15)),
             box((0.25, 0.12, 0.25), "truck", "rubber", (xback - 0.06, 0, floor - 0.1)),
             box((0.15, W - 0.04, 0.22), "truck", "rubber", (L / 2 - 0.075, 0, zb + 0.05)),
             box((0.12, W - 0.2, 0.15), "truck", "rubber", (-L / 2 + 0.3, 0, floor - 0.3))]
    # windshield on the raked part and side windows
    ws = np.array([[xfront, -W / 2, zw], [xfront, W / 2, zw], [xfront - 0.22, W / 2, cab_h - 0.08],
                   [xfront - 0.22, -W / 2, cab_h - 0.08]])
    parts.append(_inset_quad(ws, 0.1, 0.06, np.array([cab_h - 0.08 - zw, 0.0, 0.22]), "truck"))
    for side in (1.0, -1.0):
        y = side * (W / 2 + 0.02)
        q = np.array([[xback + 0.35, y, zw + 0.1], [xfront - 0.4, y, zw + 0.1], [xfront - 0.4, y, cab_h - 0.25],
                      [xback + 0.35, y, cab_h - 0.25]])
        parts.append(polygon(q, "truck", "car_glass", (0, side, 0)))
        parts.append(box((0.08, 0.08, 0.4), "truck", "chrome", (xfront - 0.3, side * (W / 2 + 0.04), cab_h - 0.75)))
        parts.append(wheel(xf, W / 2 - 0.02, side, r, 0.28, "truck", 16))
        parts.append(wheel(xr, W / 2 - 0.02, side, r, 0.28, "truck", 16))
        rear = cylinder(r, 0.28, "truck", "rubber", 16)
        parts.append(rear.transformed(pose(xr, side * (W / 2 - 0.32), r, roll=side * np.pi / 2)))
    head = np.array([[xfront + 0.02, s * (W / 2 - 0.3), 0.75] for s in (1, -1)])
    tail = np.array([[-L / 2 - 0.02, s * (W / 2 - 0.25), floor - 0.3] for s in (1, -1)])
    for c in head:
        parts.append(_light(c[0] - 0.03, c[1], c[2], (0.06, 0.3, 0.14), "truck", "headlight"))
    for c in tail:
        parts.append(_light(c[0] + 0.03, c[1], c[2], (0.06, 0.25, 0.12), "truck", "taillight"))
    out = on_ground(merge(parts))
    out.anchors = {"headlight": head, "taillight": tail}
    return out
