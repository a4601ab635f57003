"""Vehicles: cars (sedan, hatchback, estate/SUV, van) and box trucks.

Local frame: +x forward (headlights at +x), z up, origin on the ground under the centre
of the bounding box. Cars are one class (``car``) with paint, glass, rubber, chrome and
light materials; trucks likewise with class ``truck``. Glass sits 2 cm proud of the
body surface so it never z-fights with the paint.
"""

from __future__ import annotations

import numpy as np

from generator.geometry import Mesh, box, cylinder, disc, loft, merge, on_ground, polygon, pose, prism

GLASS_OFFSET = 0.02  # metres: glass in front of the body surface (>= 2 cm: no z-fighting)

#: variant -> ranges (low, high) in metres; ``rear``: notch (separate boot), hatch, box (vertical tail)
CAR_VARIANTS: dict[str, dict] = {
    "sedan": dict(L=(4.4, 4.9), W=(1.74, 1.84), H=(1.42, 1.50), r=(0.31, 0.34), sill=(0.28, 0.32), front_oh=(0.85, 1.0),
                  rear_oh=(1.0, 1.15), hood=(1.25, 1.45), ws=(0.85, 1.0), rear_run=(0.6, 0.75),
                  rear="notch", windows=2, belt=0.67),
    "hatchback": dict(L=(3.8, 4.3), W=(1.70, 1.80), H=(1.44, 1.55), r=(0.29, 0.32), sill=(0.27, 0.31), front_oh=(0.75, 0.9),
                      rear_oh=(0.6, 0.75), hood=(0.95, 1.1), ws=(0.75, 0.9), rear_run=(0.22, 0.32),
                      rear="hatch", windows=2, belt=0.65),
    "estate": dict(L=(4.4, 4.9), W=(1.78, 1.86), H=(1.55, 1.75), r=(0.33, 0.37), sill=(0.34, 0.42), front_oh=(0.85, 0.95),
                   rear_oh=(0.9, 1.05), hood=(1.05, 1.2), ws=(0.7, 0.85), rear_run=(0.1, 0.18),
                   rear="box", windows=3, belt=0.64),
    "van": dict(L=(4.5, 4.95), W=(1.78, 1.86), H=(1.75, 1.88), r=(0.31, 0.34), sill=(0.3, 0.34), front_oh=(0.85, 0.95),
                rear_oh=(0.8, 0.95), hood=(0.75, 0.9), ws=(0.95, 1.1), rear_run=(0.06, 0.1),
                rear="box", windows=3, belt=0.56),
}


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


def _interp(x: np.ndarray, pts: list[tuple[float, float]]) -> np.ndarray:
    xs, vs = zip(*sorted(pts))
    return np.interp(x, xs, vs)


def _draw(rng: np.random.Generator, spec: dict) -> dict[str, float]:
    return {k: float(rng.uniform(*v)) for k, v in spec.items() if isinstance(v, tuple)}


def _lower_body(p: dict, v: dict, xa: float, xd: float, wheels_x: tuple[float, float]) -> Mesh:
    """Lofted lower body with wheel arches cut over both axles."""
    L, W, r, sill = p["L"], p["W"], p["r"], p["sill"]
    belt = p["belt_z"]
    arch_r = 1.12 * r
    stations = {-L / 2, -L / 2 + 0.12, -L / 2 + 0.45, L / 2 - 0.45, L / 2 - 0.12, L / 2, xa, xd}
    for wx in wheels_x:
        stations |= {wx + arch_r * np.cos(t) for t in np.radians([180, 150, 120, 90, 60, 30, 0])}
    xs = np.array(sorted(stations))
    xs = xs[np.concatenate([[True], np.diff(xs) > 0.03])]
    xs[-1] = L / 2
    zb = np.full_like(xs, sill)
    for wx in wheels_x:
        inside = np.abs(xs - wx) < arch_r - 1e-6
        zb[inside] = np.maximum(zb[inside], r + 0.02 + np.sqrt(arch_r ** 2 - (xs[inside] - wx) ** 2))
    zb[0] += 0.08
    zb[-1] += 0.06
    deck = belt - (0.02 if v["rear"] == "notch" else 0.0)
    zt = _interp(xs, [(-L / 2, deck - 0.09), (-L / 2 + 0.12, deck), (xd, belt), (xa, belt),
                      (L / 2 - 0.12, p["hood_front"]), (L / 2, p["hood_front"] - 0.08)])
    wf = _interp(xs, [(-L / 2, 0.87), (-L / 2 + 0.12, 0.96), (-L / 2 + 0.45, 1.0), (L / 2 - 0.45, 1.0),
                      (L / 2 - 0.12, 0.95), (L / 2, 0.85)])
    rings = []
    for x, b, t, f in zip(xs, zb, zt, wf):
        w = W / 2 * f
        h = t - b
        side = [(w * 0.94, b), (w, b + 0.3 * h), (w, t - min(0.08, 0.3 * h)), (w * 0.9, t)]
        ring = side + [(-yy, zz) for yy, zz in side[::-1]]
        rings.append([(x, yy, zz) for yy, zz in ring])
    return loft(np.array(rings), p["cls"], "car_paint")


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


def _cabin(p: dict, v: dict, xa: float, xb: float, xc: float, xd: float) -> list[Mesh]:
    """Greenhouse: painted shell (pillars, roof) with proud glass panes."""
    W, belt, roof_z, H = p["W"], p["belt_z"], p["H"] - 0.03, p["H"]
    wb, wr = 0.9 * W / 2, 0.74 * W / 2
    prof = [(xd, belt), (xc, roof_z), ((xb + xc) / 2, H), (xb, roof_z), (xa, belt)]

    def half_w(z: float) -> float:
        return wb + (wr - wb) * (z - belt) / (roof_z - belt)

    left = np.array([(x, half_w(z), z) for x, z in prof])
    right = left * np.array([1, -1, 1])
    centre = np.array([(xa + xd) / 2, 0.0, (belt + roof_z) / 2])
    cls = p["cls"]
    parts = [polygon(left, cls, "car_paint", (0, 1, 0)), polygon(right, cls, "car_paint", (0, -1, 0))]
    for i in range(len(prof) - 1):
        q = np.array([left[i], left[i + 1], right[i + 1], right[i]])
        parts.append(polygon(q, cls, "car_paint", q.mean(0) - centre))
    # windshield (a -> b) and rear glass (d -> c)
    for lo, hi in ((4, 3), (0, 1)):
        q = np.array([right[lo], left[lo], left[hi], right[hi]])
        n = np.cross(q[1] - q[0], q[3] - q[0])
        n = n if np.dot(n, q.mean(0) - centre) > 0 else -n
        parts.append(_inset_quad(q, 0.07, 0.05, n, cls))
    # side windows between the A- and C/D-pillars, split by B (and C) pillars
    z = np.array([belt + 0.05, roof_z - 0.06])                     # sill and top of the glass
    f = (z - belt) / (roof_z - belt)
    front = xa + f * (xb - xa) - 0.1                                 # behind the A-pillar
    rear = xd + f * (xc - xd) + 0.12                                 # ahead of the C/D-pillar
    n_win = v["windows"]
    cuts = np.linspace(0.0, 1.0, n_win + 1)
    tilt = (wb - wr) / (roof_z - belt)
    for side in (1.0, -1.0):
        normal = np.array([0.0, side, tilt]) / np.hypot(1.0, tilt)
        for k in range(n_win):
            s0 = cuts[k] + (0.03 if k else 0.0)
            s1 = cuts[k + 1] - (0.03 if k < n_win - 1 else 0.0)
            xs0, xs1 = rear + s0 * (front - rear), rear + s1 * (front - rear)
            pts = [(xs0[0], z[0]), (xs1[0], z[0]), (xs1[1], z[1]), (xs0[1], z[1])]
            q = np.array([(x, side * half_w(zz), zz) for x, zz in pts]) + GLASS_OFFSET * normal
            parts.append(polygon(q, cls, "car_glass", normal))
    return parts


def car(rng: np.random.Generator, variant: str | None = None) -> Mesh:
    """A passenger car with a random body style and real-world proportions.

    Parameters
    ----------
    rng : numpy.random.Generator
    variant : {"sedan", "hatchback", "estate", "van"}, optional
        Drawn from the rng when omitted.

    Returns
    -------
    Mesh
        Class ``car``; 3.8-5.0 m long, 1.7-2.0 m wide (mirrors included), 1.4-1.9 m high.
        Anchors ``"headlight"`` (2, 3) and ``"taillight"`` (2, 3) on the lamp faces.
    """
    if variant is None:
        variant = str(rng.choice(sorted(CAR_VARIANTS)))
    if variant not in CAR_VARIANTS:
        raise ValueError(f"car variant must be one of {sorted(CAR_VARIANTS)}, got {variant!r}")
    v = CAR_VARIANTS[variant]
    p = _draw(rng, v)
    p["cls"] = "car"
    L, W, H, r = p["L"], p["W"], p["H"], p["r"]
    p["belt_z"] = v["belt"] * H + rng.uniform(-0.02, 0.02)
    p["hood_front"] = p["belt_z"] - rng.uniform(0.12, 0.2)
    xf, xr = L / 2 - p["front_oh"], -L / 2 + p["rear_oh"]
    xa = L / 2 - p["hood"]
    xb = xa - p["ws"]
    xd = -L / 2 + (0.35 + 0.25 * rng.random() if v["rear"] == "notch" else 0.04)
    xc = xd + p["rear_run"]
    if v["rear"] == "notch":
        xc = min(xc, xb - 0.9)
    parts = [_lower_body(p, v, xa, xd, (xr, xf))] + _cabin(p, v, xa, xb, xc, xd)
    for x in (xr, xf):
        for side in (1.0, -1.0):
            parts.append(wheel(x, W / 2 - 0.015, side, r, 0.2, "car"))
    top_f, top_r = p["hood_front"] - 0.08, p["belt_z"] - 0.09
    yl, yt = W / 2 * 0.85 - 0.2, W / 2 * 0.87 - 0.17
    head = np.array([[L / 2 + 0.02, s * yl, top_f - 0.09] for s in (1, -1)])
    tail = np.array([[-L / 2 - 0.02, s * yt, top_r - 0.1] for s in (1, -1)])
    for c in head:
        parts.append(_light(c[0] - 0.025, c[1], c[2], (0.05, 0.3, 0.1), "car", "headlight"))
    for c in tail:
        parts.append(_light(c[0] + 0.025, c[1], c[2], (0.05, 0.26, 0.12), "car", "taillight"))
    parts.append(box((0.04, 2 * yl - 0.4, 0.12), "car", "rubber", (L / 2 - 0.005, 0, top_f - 0.2)))
    for side in (1.0, -1.0):
        y = side * (0.9 * W / 2 + 0.06)
        parts.append(box((0.08, 0.14, 0.1), "car", "car_paint", (xa - 0.15, y, p["belt_z"] + 0.1)))
    out = on_ground(merge(parts))
    out.anchors = {"headlight": head, "taillight": tail}
    return out


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
    parts = [cab, box((x_box0 + L / 2, W, H - floor), "truck", "truck_paint", ((x_box0 - L / 2) / 2, 0, (H + floor) / 2)),
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
        parts.append(cylinder(r, 0.28, "truck", "rubber", 16).transformed(pose(xr, side * (W / 2 - 0.32), r, roll=side * np.pi / 2)))
    head = np.array([[xfront + 0.02, s * (W / 2 - 0.3), 0.75] for s in (1, -1)])
    tail = np.array([[-L / 2 - 0.02, s * (W / 2 - 0.25), floor - 0.3] for s in (1, -1)])
    for c in head:
        parts.append(_light(c[0] - 0.03, c[1], c[2], (0.06, 0.3, 0.14), "truck", "headlight"))
    for c in tail:
        parts.append(_light(c[0] + 0.03, c[1], c[2], (0.06, 0.25, 0.12), "truck", "taillight"))
    out = on_ground(merge(parts))
    out.anchors = {"headlight": head, "taillight": tail}
    return out
