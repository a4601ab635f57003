"""Public transport: city buses and articulated trams (track pieces: :mod:`assets_procedural.tracks`).

Local frame: +x forward (headlights at +x), z up, origin on the ground (tyre or wheel
bottoms; for a tram the rail top) under the centre of the footprint. Buses are class ``bus``,
trams ``on_rails`` (pantograph included). Glass sits 2 cm proud of the body, as on cars.
"""

from __future__ import annotations

import numpy as np

from assets_procedural.parts import centred, rounded_section, sweep, two_link, wheel_cylinder
from assets_procedural.tracks import GAUGE
from generator.geometry import Mesh, box, cylinder, loft, merge, polygon, pose

GLASS = 0.02          # metres: glass in front of the body surface


def _body(stations: list[tuple[float, float, float, float, float]], cls: str, material: str, r_top: float,
          r_bottom: float = 0.05) -> Mesh:
    """Loft of rounded cross-sections; each station is (x, half width, z bottom, z top, corner radius scale)."""
    rings = []
    for x, hw, z0, z1, rs in stations:
        sec = rounded_section(hw, z0, z1, r_top * rs, r_bottom)
        rings.append(np.c_[np.full(len(sec), x), sec])
    return loft(np.array(rings), cls, material)


def _panes(x0: float, x1: float, z0: float, z1: float, y: float, pitch: float, cls: str, gap: float = 0.1,
           skip: list[tuple[float, float]] = ()) -> list[Mesh]:
    """Glass panes about ``pitch`` long filling [x0, x1] in the plane |y| = const (facing sign(y)),
    leaving out the ``skip`` ranges (doors); pillars ``gap`` wide between panes."""
    side = np.sign(y)
    free, start = [], x0
    for s0, s1 in sorted(skip):
        if s0 > start:
            free.append((start, min(s0, x1)))
        start = max(start, s1)
    if start < x1:
        free.append((start, x1))
    out = []
    for a0, a1 in free:
        if a1 - a0 < 0.4:
            continue
        n = max(1, int(round((a1 - a0) / pitch)))
        edges = np.linspace(a0, a1, n + 1)
        for a, b in zip(edges[:-1], edges[1:], strict=False):
            a, b = a + gap / 2, b - gap / 2
            q = np.array([[a, y, z0], [b, y, z0], [b, y, z1], [a, y, z1]])
            out.append(polygon(q, cls, "car_glass", (0, side, 0)))
    return out


def _lights(front_x: float, rear_x: float, y: float, z_head: float, z_tail: float, cls: str) -> tuple[list[Mesh], dict]:
    parts, head, tail = [], [], []
    for s in (1.0, -1.0):
        head.append([front_x + 0.02, s * y, z_head])
        tail.append([rear_x - 0.02, s * y, z_tail])
        parts.append(box((0.05, 0.3, 0.14), cls, "headlight", (front_x - 0.005, s * y, z_head)))
        parts.append(box((0.05, 0.16, 0.3), cls, "taillight", (rear_x + 0.005, s * y, z_tail)))
    return parts, {"headlight": np.array(head), "taillight": np.array(tail)}


# -- bus --------------------------------------------------------------------------------------------

def bus(rng: np.random.Generator, length: float | None = None, doors: int | None = None) -> Mesh:
    """A low-floor city bus: rounded body, window band, two or three doors on the right (-y),
    single front and twin rear wheels, a roof unit, rear-view mirrors on arms.

    Parameters
    ----------
    length : float, optional
        10.5-12.2 m (midi to standard); drawn when omitted.
    doors : {2, 3}, optional
        Doors on the right side; drawn when omitted.

    Returns
    -------
    Mesh
        Class ``bus``; 2.5-2.75 m wide (mirrors), 3.0-3.35 m high; anchors ``"headlight"`` and
        ``"taillight"`` (2, 3).
    """
    L = float(rng.uniform(10.5, 12.2)) if length is None else float(length)
    if not 8.0 <= L <= 13.5:
        raise ValueError(f"bus length must be in [8, 13.5] m, got {L}")
    doors = int(rng.choice([2, 3])) if doors is None else int(doors)
    if doors not in (2, 3):
        raise ValueError(f"bus doors must be 2 or 3, got {doors}")
    cls = "bus"
    W, H = float(rng.uniform(2.5, 2.55)), float(rng.uniform(2.95, 3.1))
    r = float(rng.uniform(0.47, 0.5))
    xf, xr = L / 2 - float(rng.uniform(2.6, 2.8)), -L / 2 + float(rng.uniform(3.1, 3.5))
    skirt = 0.32
    arch = r + 0.07
    xs = {-L / 2, -L / 2 + 0.15, L / 2 - 0.15, L / 2}
    for wx in (xf, xr):
        xs |= {wx + arch * np.cos(t) for t in np.radians([180, 150, 120, 90, 60, 30, 0])}
    stations = []
    for x in sorted(xs):
        zb = skirt
        for wx in (xf, xr):
            if abs(x - wx) < arch - 1e-6:
                zb = max(zb, r + 0.05 + np.sqrt(arch ** 2 - (x - wx) ** 2))
        end = abs(x) > L / 2 - 0.01
        hw = W / 2 * (0.97 if end else 1.0)
        zt = H - (0.06 if end else 0.0)
        stations.append((x, hw, zb + (0.04 if end else 0.0), zt, 1.0))
    parts = [_body(stations, cls, "truck_paint", r_top=0.22, r_bottom=0.04)]
    # windows: a band on both sides, doors on the right; windscreen, rear window
    z0, z1 = 1.12, H - 0.32
    door_w = 1.2
    door_x = [L / 2 - 0.25 - door_w, (xf + xr) / 2 + 0.4 - door_w / 2]
    if doors == 3:
        door_x.append(xr - arch - 0.1 - door_w)
    for s in (1.0, -1.0):
        skip = [(d - 0.12, d + door_w + 0.12) for d in door_x] if s < 0 else [(L / 2 - 1.3, L / 2)]
        parts += _panes(-L / 2 + 0.7, L / 2 - 0.3, z0, z1, s * (W / 2 + GLASS), 1.35, cls, skip=skip)
    for d in door_x:
        for k in range(2):
            a = d + k * door_w / 2 + 0.03
            q = np.array([[a, -(W / 2 + GLASS), skirt + 0.1], [a + door_w / 2 - 0.06, -(W / 2 + GLASS), skirt + 0.1],
                          [a + door_w / 2 - 0.06, -(W / 2 + GLASS), H - 0.3], [a, -(W / 2 + GLASS), H - 0.3]])
            parts.append(polygon(q, cls, "car_glass", (0, -1, 0)))
    fx, rx = L / 2 + GLASS, -L / 2 - GLASS
    hw = W / 2 * 0.97 - 0.12
    parts.append(polygon(np.array([[fx, -hw, 1.0], [fx, hw, 1.0], [fx, hw, H - 0.42], [fx, -hw, H - 0.42]]), cls,
                         "car_glass", (1, 0, 0)))
    parts.append(box((0.04, 2 * hw, 0.22), cls, "tl_housing", (L / 2 + GLASS, 0.0, H - 0.27)))
    parts.append(polygon(np.array([[rx, -hw + 0.2, 1.7], [rx, hw - 0.2, 1.7], [rx, hw - 0.2, H - 0.4],
                                   [rx, -hw + 0.2, H - 0.4]]), cls, "car_glass", (-1, 0, 0)))
    # bumpers, roof unit, mirrors
    parts.append(box((0.12, W - 0.1, 0.28), cls, "rubber", (L / 2 - 0.02, 0.0, skirt + 0.12)))
    parts.append(box((0.12, W - 0.1, 0.28), cls, "rubber", (-L / 2 + 0.02, 0.0, skirt + 0.12)))
    parts.append(box((2.4, 1.7, 0.26), cls, "truck_paint", (xr + 1.6, 0.0, H + 0.13 - 0.01)))
    for s in (1.0, -1.0):
        base = np.array([L / 2 - 0.05, s * (W / 2 - 0.05), H - 0.25])
        parts.append(sweep(np.array([base, base + [0.25, s * 0.12, 0.0], base + [0.35, s * 0.18, -0.25]]), 0.02, cls,
                           "pole_metal", 5))
        parts.append(box((0.06, 0.2, 0.35), cls, "tl_housing", tuple(base + [0.35, s * 0.18, -0.45])))
    # wheels: single front, twin rear
    for s in (1.0, -1.0):
        yo = W / 2 - 0.05
        parts.append(wheel_cylinder(xf, s * (yo - 0.15), r, 0.3, cls))
        parts.append(wheel_cylinder(xr, s * (yo - 0.15), r, 0.3, cls))
        parts.append(wheel_cylinder(xr, s * (yo - 0.47), r, 0.3, cls, hub="rubber"))
    lights, anchors = _lights(L / 2, -L / 2, W / 2 - 0.3, 0.62, 1.0, cls)
    parts += lights
    out = merge(parts)
    out.anchors = anchors
    return centred(out)


# -- tram -------------------------------------------------------------------------------------------

def _pantograph(x: float, z_roof: float, height: float, cls: str) -> list[Mesh]:
    """A single-arm pantograph on a roof at ``z_roof`` whose collector head is ``height`` above it."""
    parts = []
    for dx in (-0.55, 0.55):
        for dy in (-0.45, 0.45):
            parts.append(cylinder(0.06, 0.16, cls, "chrome", 8, z0=z_roof).transformed(pose(x + dx, dy)))
    zb = z_roof + 0.16
    parts.append(box((1.4, 1.1, 0.07), cls, "pole_metal", (x, 0.0, zb + 0.035)))
    hinge = np.array([x - 0.6, 0.0, zb + 0.15])
    head = np.array([x - 0.1, 0.0, z_roof + height])
    arm = max(0.9, 0.55 * float(np.linalg.norm(head - hinge)) + 0.1)
    knee, head = two_link(hinge, head, arm, arm, np.array([1.0, 0.0, 0.0]))
    for s in (1.0, -1.0):
        parts.append(sweep(np.array([hinge + [0, s * 0.3, 0], knee + [0, s * 0.04, 0]]), 0.025, cls, "pole_metal", 6))
    parts.append(sweep(np.array([knee, head]), 0.02, cls, "pole_metal", 6))
    parts.append(sweep(np.array([hinge + [0.2, 0, -0.05], hinge + 0.45 * (knee - hinge) + [0, 0, -0.02]]), 0.012, cls,
                       "chrome", 5))
    for dx in (-0.12, 0.12):
        bar = np.array([head + [dx, -0.62, 0.0], head + [dx, 0.62, 0.0]])
        parts.append(sweep(bar, (0.02, 0.03), cls, "chrome", 6))
    for s in (1.0, -1.0):
        parts.append(sweep(np.array([head + [0.0, s * 0.6, 0.0], head + [0.0, s * 0.8, -0.05],
                                     head + [0.0, s * 0.9, -0.18]]),
                           0.015, cls, "pole_metal", 5))
    parts.append(box((0.3, 0.6, 0.04), cls, "pole_metal", tuple(head + [0.0, 0.0, -0.05])))
    return parts


def tram(rng: np.random.Generator, sections: int | None = None, bend_deg: float = 0.0,
         pantograph_height: float | None = None) -> Mesh:
    """A low-floor articulated tram: 3 or 5 body sections joined by bellows, cab noses at both
    ends, a window band, double doors on the right (-y), wheels peeking under the skirt and a
    single-arm pantograph on the middle section.

    Parameters
    ----------
    sections : {3, 5}, optional
        Body sections (about 20-24 m or 30-34 m long); drawn when omitted.
    bend_deg : float
        Yaw between successive sections (a tram on a curve), degrees, |bend| <= 15.
    pantograph_height : float, optional
        Collector head above the roof, metres: 0.35 lowered, 0.9-1.6 raised (drawn).

    Returns
    -------
    Mesh
        Class ``on_rails``; 2.3-2.65 m wide, 3.4-5.2 m high (pantograph); wheel bottoms (rail
        top) at z = 0; anchors ``"headlight"`` and ``"taillight"`` (2, 3).
    """
    n = int(rng.choice([3, 5])) if sections is None else int(sections)
    if n not in (3, 5):
        raise ValueError(f"tram sections must be 3 or 5, got {n}")
    if abs(bend_deg) > 15:
        raise ValueError(f"tram bend_deg must be within +-15, got {bend_deg}")
    ph = float(rng.uniform(0.9, 1.6)) if pantograph_height is None else float(pantograph_height)
    cls = "on_rails"
    W, H = float(rng.uniform(2.3, 2.65)), float(rng.uniform(3.35, 3.5))
    gap = 0.32
    lengths = [float(rng.uniform(7.0, 8.0))] + [float(rng.uniform(5.0, 6.8)) for _ in range(n - 2)] + [0.0]
    lengths[-1] = lengths[0]
    skirt = 0.16
    wheel_r = 0.3
    sections_m: list[Mesh] = []
    anchors_local = {}
    for k, Lk in enumerate(lengths):
        x0, x1 = -Lk / 2, Lk / 2
        front, rear = k == 0, k == n - 1
        st = []
        if rear:
            st += [(x0, W / 2 * 0.78, 0.3, H - 0.55, 0.6), (x0 + 0.3, W / 2 * 0.93, 0.2, H - 0.1, 0.9),
                   (x0 + 0.9, W / 2, skirt, H, 1.0)]
        else:
            st += [(x0, W / 2, skirt, H, 1.0)]
        if front:
            st += [(x1 - 0.9, W / 2, skirt, H, 1.0), (x1 - 0.3, W / 2 * 0.93, 0.2, H - 0.1, 0.9),
                   (x1, W / 2 * 0.78, 0.3, H - 0.55, 0.6)]
        else:
            st += [(x1, W / 2, skirt, H, 1.0)]
        parts = [_body(st, cls, "truck_paint", r_top=0.3, r_bottom=0.05)]
        # window band, doors on the right
        wx0 = x0 + (1.0 if rear else 0.3)
        wx1 = x1 - (1.0 if front else 0.3)
        door_w = 1.3
        door_x = [(wx0 + wx1) / 2 - door_w / 2] if Lk > 5.5 else []
        for s in (1.0, -1.0):
            skip = [(d - 0.12, d + door_w + 0.12) for d in door_x] if s < 0 else []
            parts += _panes(wx0, wx1, 0.95, H - 0.4, s * (W / 2 + GLASS), 1.3, cls, skip=skip)
        for d in door_x:
            for j in range(2):
                a = d + j * door_w / 2 + 0.03
                q = np.array([[a, -(W / 2 + GLASS), 0.3], [a + door_w / 2 - 0.06, -(W / 2 + GLASS), 0.3],
                              [a + door_w / 2 - 0.06, -(W / 2 + GLASS), H - 0.35], [a, -(W / 2 + GLASS), H - 0.35]])
                parts.append(polygon(q, cls, "car_glass", (0, -1, 0)))
        for end, sign in ((front, 1.0), (rear, -1.0)):
            if not end:
                continue
            xe = sign * (Lk / 2 + GLASS)
            hw = W / 2 * 0.78 - 0.1
            q = np.array([[xe, -hw, 1.05], [xe, hw, 1.05], [xe, hw, H - 0.62], [xe, -hw, H - 0.62]])
            parts.append(polygon(q, cls, "car_glass", (sign, 0, 0)))
            zl = 0.75
            for s in (1.0, -1.0):
                mat = "headlight" if sign > 0 else "taillight"
                parts.append(
                    box((0.05, 0.22, 0.12), cls, mat, (sign * (Lk / 2 - 0.005), s * (W / 2 * 0.78 - 0.25), zl))
                )
                anchors_local.setdefault("headlight" if sign > 0 else "taillight", []).append(
                    (k, np.array([sign * (Lk / 2 + 0.02), s * (W / 2 * 0.78 - 0.25), zl])))
        # bogies under the odd sections (1st, 3rd, 5th): two axles, wheels just inside the skirt
        if k % 2 == 0:
            for ax in (-0.9, 0.9):
                for s in (1.0, -1.0):
                    parts.append(wheel_cylinder(ax, s * (GAUGE / 2 + 0.06), wheel_r, 0.12, cls, hub="pole_metal"))
            parts.append(box((2.6, GAUGE - 0.1, 0.25), cls, "pole_metal", (0.0, 0.0, wheel_r)))
        # roof equipment
        if k == n // 2:
            parts += _pantograph(0.0, H, ph, cls)
        else:
            parts.append(box((min(2.4, Lk - 1.5), 1.4, 0.3), cls, "truck_paint", (0.0, 0.0, H + 0.14)))
        sections_m.append(merge(parts))
    # chain the sections: section 0 in front; the bellows sit on the pivots
    out, heading = [], 0.0
    front_end = np.zeros(2)
    anchors = {}
    for k, (Lk, m) in enumerate(zip(lengths, sections_m, strict=False)):
        d = np.array([np.cos(heading), np.sin(heading)])
        centre = front_end - d * Lk / 2
        t = pose(centre[0], centre[1], 0.0, yaw=heading)
        out.append(m.transformed(t))
        for name, pts in anchors_local.items():
            for kk, p in pts:
                if kk == k:
                    anchors.setdefault(name, []).append((t @ np.append(p, 1.0))[:3])
        if k < n - 1:
            pivot = centre - d * (Lk / 2 + gap / 2)
            mid_heading = heading + np.radians(bend_deg) / 2
            bell = _body([(-gap / 2 - 0.05, W / 2 * 0.9, 0.45, H - 0.12, 0.6),
                          (gap / 2 + 0.05, W / 2 * 0.9, 0.45, H - 0.12, 0.6)],
                         cls, "rubber", r_top=0.3)
            out.append(bell.transformed(pose(pivot[0], pivot[1], 0.0, yaw=mid_heading)))
            heading += np.radians(bend_deg)
            d2 = np.array([np.cos(heading), np.sin(heading)])
            front_end = pivot - d2 * gap / 2
    tr = merge(out)
    tr.anchors = {k: np.array(v) for k, v in anchors.items()}
    return centred(tr)
