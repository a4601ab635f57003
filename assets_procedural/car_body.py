"""Passenger-car bodies as one lofted shell with curved profiles, by body type.

A body is skinned (:func:`generator.geometry.loft`) over cross-sections taken along x, front
(+x) to rear. Each section is a closed outline whose heights come from two side-view curves
and whose widths come from a plan-view curve:

* the top line ``U(x)``: bumper, hood, windscreen, roof, rear window, boot deck or tailgate,
  a polyline of key points whose corners are rounded by arcs of a radius per corner (tight
  at a tailgate, wide at the windscreen), so every transition is curved;
* the bottom line: the ground clearance, cut by a wheel arch over each axle;
* the shoulder (belt) line ``S(x)`` where the side turns in towards the roof (tumblehome).

Glass is part of the same shell: the faces of the greenhouse rows between the pillars take
``car_glass`` (side windows, windscreen, rear window), so the glass follows the body's curves
and nothing z-fights. The lowest row (sills, under-body) and the pillars between side windows are
``car_trim`` (black plastic: the glass reads as one band, as on most cars since the 2000s).

Local frame: +x forward, z up, the body's lowest point at ``clearance``; wheels are added by
:mod:`assets_procedural.vehicle`.
"""

from __future__ import annotations

import numpy as np

from generator.geometry import Mesh, loft, resolve_ids

#: body type -> ranges (low, high), metres, from the dimensions of common European/US models
#: (e.g. sedan ~ VW Passat / Toyota Camry, hatchback ~ VW Golf / Renault Clio, estate ~ Skoda
#: Octavia Combi, SUV ~ Toyota RAV4 / VW Tiguan, van ~ VW Touran / Renault Espace (MPV),
#: pickup ~ Ford Ranger / Toyota Hilux double cab).
#: ``L`` length, ``W`` body width without mirrors, ``H`` height, ``r`` tyre radius, ``clear``
#: ground clearance of the sills, ``front_oh``/``rear_oh`` overhangs (bumper to axle), ``hood``
#: bumper to windscreen base, ``ws`` windscreen run (base to roof front), ``back`` roof end to
#: the end of the rear glass, ``deck`` rear glass to the rear end; ``belt`` shoulder height as a
#: fraction of ``H``; ``pillars`` x-fractions of the side glass where pillars (B, C) stand.
BODY_TYPES: dict[str, dict] = {
    "sedan": dict(L=(4.45, 4.95), W=(1.76, 1.86), H=(1.40, 1.49), r=(0.31, 0.335), clear=(0.14, 0.17),
                  front_oh=(0.88, 1.0), rear_oh=(1.0, 1.12), hood=(1.15, 1.35), ws=(0.75, 0.9), back=(0.55, 0.7),
                  deck=(0.45, 0.6), belt=0.66, pillars=(0.5,), tail="notch"),
    "hatchback": dict(L=(3.85, 4.3), W=(1.70, 1.80), H=(1.42, 1.52), r=(0.29, 0.32), clear=(0.13, 0.16),
                      front_oh=(0.75, 0.88), rear_oh=(0.6, 0.75), hood=(0.9, 1.05), ws=(0.7, 0.85),
                      back=(0.3, 0.42), deck=(0.06, 0.1), belt=0.64, pillars=(0.55,), tail="hatch"),
    "estate": dict(L=(4.5, 4.95), W=(1.78, 1.86), H=(1.45, 1.55), r=(0.31, 0.335), clear=(0.14, 0.17),
                   front_oh=(0.88, 0.98), rear_oh=(0.95, 1.08), hood=(1.1, 1.3), ws=(0.75, 0.88), back=(0.22, 0.3),
                   deck=(0.05, 0.08), belt=0.64, pillars=(0.42, 0.74), tail="box"),
    "suv": dict(L=(4.4, 4.85), W=(1.8, 1.89), H=(1.62, 1.76), r=(0.35, 0.38), clear=(0.19, 0.22),
                front_oh=(0.85, 0.98), rear_oh=(0.9, 1.05), hood=(1.05, 1.25), ws=(0.7, 0.82), back=(0.18, 0.26),
                deck=(0.05, 0.08), belt=0.63, pillars=(0.45, 0.76), tail="box"),
    "van": dict(L=(4.5, 4.95), W=(1.79, 1.88), H=(1.68, 1.85), r=(0.31, 0.34), clear=(0.15, 0.18),
                front_oh=(0.85, 0.95), rear_oh=(0.85, 0.98), hood=(0.75, 0.9), ws=(0.95, 1.1), back=(0.12, 0.18),
                deck=(0.04, 0.06), belt=0.56, pillars=(0.4, 0.72), tail="box"),
    "pickup": dict(L=(5.1, 5.4), W=(1.82, 1.89), H=(1.76, 1.84), r=(0.37, 0.395), clear=(0.21, 0.24),
                   front_oh=(0.9, 1.0), rear_oh=(1.25, 1.4), hood=(1.25, 1.4), ws=(0.75, 0.85), back=(0.08, 0.1),
                   deck=(1.45, 1.6), belt=0.6, pillars=(0.5,), tail="bed"),
}

PILLAR_M = 0.1  #: width of a B/C-pillar between two side windows, metres

#: half-width of the section as a fraction of W/2, against distance from the nearest end (metres)
_PLAN = [(0.0, 0.84), (0.08, 0.92), (0.25, 0.975), (0.55, 1.0)]


def draw_dimensions(rng: np.random.Generator, body: str) -> dict[str, float]:
    """Draw one car's dimensions (metres) of ``body`` from :data:`BODY_TYPES`."""
    t = BODY_TYPES[body]
    p = {k: float(rng.uniform(*v)) for k, v in t.items() if isinstance(v, tuple) and k != "pillars"}
    p["belt_z"] = t["belt"] * p["H"] + float(rng.uniform(-0.015, 0.015))
    return p


def round_corners(pts: np.ndarray, radii: list[float], n: int = 4) -> np.ndarray:
    """Round each interior corner of an open polyline by a quadratic Bezier arc.

    Parameters
    ----------
    pts : (k, 2) float
        The polyline, metres.
    radii : list of float, length k
        How far (metres) from each corner the arc starts on both sides (capped at 45 % of the
        neighbouring segments); the ends' entries are ignored.
    n : int
        Points per arc.

    Returns
    -------
    (m, 2) float
        The rounded polyline; the ends stay.
    """
    p = np.asarray(pts, float)
    out = [p[0]]
    t = np.linspace(0.0, 1.0, n)[:, None]
    for i in range(1, len(p) - 1):
        a, c = p[i - 1] - p[i], p[i + 1] - p[i]
        la, lc = np.linalg.norm(a), np.linalg.norm(c)
        r = min(radii[i], 0.45 * la, 0.45 * lc)
        p0, p2 = p[i] + a * r / la, p[i] + c * r / lc
        out.extend((1 - t) ** 2 * p0 + 2 * (1 - t) * t * p[i] + t ** 2 * p2)
    out.append(p[-1])
    return np.array(out)


def key_points(p: dict, body: str) -> dict:
    """x of the side-view landmarks: ``xa`` windscreen base, ``xb`` roof front, ``xc`` roof end,
    ``xd`` end of the rear glass, ``xf``/``xr`` front and rear axles, ``glass_front``/``glass_back``
    the ends of the side glass and ``pillars`` (list) the B/C-pillars between them."""
    tail = BODY_TYPES[body]["tail"]
    L = p["L"]
    xa = L / 2 - p["hood"]
    xb = xa - p["ws"]
    xd = -L / 2 + p["deck"]
    xc = xd + p["back"]
    if tail == "bed":                         # cab ends where the bed starts
        xc, xd = xd + p["back"], xd
    # side glass runs from behind the A-pillar to ahead of the C/D-pillar, split by pillars
    front, back = xa - 0.06, xd + {"notch": 0.18, "bed": 0.12}.get(tail, 0.08)
    pillars = [back + f * (front - back) for f in BODY_TYPES[body]["pillars"]]
    return dict(xa=xa, xb=xb, xc=xc, xd=xd, xf=L / 2 - p["front_oh"], xr=-L / 2 + p["rear_oh"],
                glass_front=front, glass_back=back, pillars=pillars)


def top_line(p: dict, k: dict, tail: str) -> np.ndarray:
    """(n, 2) points (x, z) of the rounded top line, rear to front (x increasing)."""
    L, H, belt = p["L"], p["H"], p["belt_z"]
    hood_front = belt - 0.1 - 0.05 * (tail == "bed")
    nose = hood_front - 0.14
    cowl = belt + 0.03
    deck = {"notch": belt + 0.02, "hatch": belt - 0.04, "box": belt - 0.06, "bed": belt + 0.02}[tail]
    tail_top = {"notch": deck - 0.05, "hatch": deck - 0.1, "box": deck - 0.12, "bed": deck}[tail]
    roof_back = {"notch": 0.3, "hatch": 0.18, "box": 0.14, "bed": 0.05}[tail]
    pts = [(-L / 2, tail_top - 0.1), (-L / 2 + 0.02, tail_top), (k["xd"], deck), (k["xc"], H), (k["xb"], H),
           (k["xa"], cowl), (L / 2 - 0.1, hood_front), (L / 2, nose)]
    radii = [0, 0.02, 0.1 if tail == "box" else 0.15, roof_back, 0.35, 0.2, 0.1, 0]
    if tail == "bed":                         # vertical cab back wall, then the bed rail
        pts = [(-L / 2, deck - 0.08), (-L / 2 + 0.02, deck), (k["xd"] - 0.04, deck), (k["xd"], H - 0.05),
               (k["xc"], H), (k["xb"], H), (k["xa"], cowl), (L / 2 - 0.1, hood_front), (L / 2, nose)]
        radii = [0, 0.02, 0.02, 0.03, roof_back, 0.35, 0.2, 0.1, 0]
    out = round_corners(np.array(pts), radii)
    return out[np.concatenate([[True], np.diff(out[:, 0]) > 1e-4])]


def stations(p: dict, k: dict, max_gap: float = 0.42) -> np.ndarray:
    """(s,) float x of the sections: the ends and the nose/tail rounding, the landmarks, the pillars
    and both wheel arches; long gaps between them split evenly (at most ``max_gap`` metres)."""
    L, ar = p["L"], p["r"] + 0.06
    xs = {-L / 2, L / 2, -L / 2 + 0.05, L / 2 - 0.05, -L / 2 + 0.18, L / 2 - 0.18, k["xa"], k["xb"], k["xc"], k["xd"],
          k["xc"] - 0.08, k["xb"] + 0.15}
    xs |= {xp + d for xp in k["pillars"] for d in (-PILLAR_M / 2, PILLAR_M / 2)}
    for wx in (k["xf"], k["xr"]):
        xs |= {wx + ar * np.cos(a) for a in np.radians([180, 145, 110, 70, 35, 0])}
    xs = np.array(sorted(x for x in xs if -L / 2 <= x <= L / 2))
    xs = xs[np.concatenate([[True], np.diff(xs) > 0.03])]
    xs[-1] = L / 2
    fill = [np.linspace(a, b, int(np.ceil((b - a) / max_gap)) + 1)[1:-1] for a, b in zip(xs[:-1], xs[1:], strict=False)]
    return np.sort(np.concatenate([xs, *fill]))


def body_shell(p: dict, body: str, cls: str = "car") -> tuple[Mesh, dict]:
    """The lofted shell of one car and its landmarks.

    Parameters
    ----------
    p : dict
        Dimensions from :func:`draw_dimensions`.
    body : str
        A key of :data:`BODY_TYPES`.

    Returns
    -------
    shell : Mesh
        Class ``cls``; materials ``car_body`` (paint, shaded smooth), ``car_glass``, ``car_trim``;
        closed (end caps).
    info : dict
        ``xs`` (s,) stations, ``top``/``shoulder``/``bottom``/``half_w`` (s,) per station, ``rings``
        (s, 15, 3) the lofted sections (points 0-7 the +y side, bottom to crown), the landmarks of
        :func:`key_points`.
    """
    t = BODY_TYPES[body]
    tail = t["tail"]
    k = key_points(p, body)
    L, W, H, belt, r = p["L"], p["W"], p["H"], p["belt_z"], p["r"]
    xs = stations(p, k)
    tl = top_line(p, k, tail)
    U = np.interp(xs, tl[:, 0], tl[:, 1])
    rise = np.clip((k["xa"] - xs) / max(k["xa"] - k["xd"], 1e-6), 0, 1)
    S = np.minimum(belt + 0.04 * rise, U - 0.05)               # the belt line rises slightly to the rear
    zb = np.full_like(xs, p["clear"])
    ar = r + 0.06
    for wx in (k["xf"], k["xr"]):
        inside = np.abs(xs - wx) < ar - 1e-6
        zb[inside] = np.maximum(zb[inside], r + np.sqrt(ar ** 2 - (xs[inside] - wx) ** 2))
    end_d = np.minimum(L / 2 - xs, xs + L / 2)
    zb = zb + np.interp(end_d, [0.0, 0.06, 0.2], [0.1, 0.04, 0.0])   # bumpers curve up underneath
    half = W / 2 * np.interp(end_d, *zip(*_PLAN, strict=False))
    g = np.clip((U - S) / max(p["H"] - belt, 1e-6), 0, 1)        # 0 on hood/deck, 1 under the roof
    w_top = half * (0.92 - 0.22 * g)             # the greenhouse leans in (tumblehome)
    rings = []
    # the roof domes fore and aft: its ends (and the roof rails) sit up to 2 cm below its middle
    roof = (xs < k["xb"]) & (xs > k["xc"])
    mid, half_run = (k["xb"] + k["xc"]) / 2, max((k["xb"] - k["xc"]) / 2, 1e-6)
    U = U - np.where(roof, 0.02 * ((xs - mid) / half_run) ** 2, 0.0) * g_roof(U, S, H, belt)
    for x, b, s_, u, w, wt in zip(xs, zb, S, U, half, w_top, strict=False):
        ws = 0.975 * w
        gg = g_roof(u, s_, H, belt)
        z4 = s_ + 0.55 * (u - s_)
        zr = u - min(0.05 + 0.03 * gg, 0.3 * (u - s_))            # a rounder roof edge over the cabin
        w4 = ws - 0.42 * (ws - wt)
        side = [(0.93 * w, b), (0.985 * w, b + min(0.1, 0.3 * (s_ - b))), (w, b + 0.5 * (s_ - b)), (ws, s_),
                (w4, z4), (wt, zr), (0.7 * wt, u - 0.012 * gg)]
        crown = u + 0.012 + 0.03 * (u - s_) / max(H - belt, 1e-6)
        ring = side + [(0.0, crown)] + [(-y, z) for y, z in side[::-1]]
        rings.append([(x, y, z) for y, z in ring])
    shell = loft(np.array(rings), cls, "car_body")
    _paint_regions(shell, xs, t, k, len(rings[0]))
    info = dict(k, xs=xs, top=U, shoulder=S, bottom=zb, half_w=half, tail=tail, rings=np.array(rings))
    return shell, info


def g_roof(u, s, H: float, belt: float):
    """0 where the top line runs at the shoulder (hood, deck), 1 under the roof: how much of the cabin's
    rounding a section takes."""
    return np.clip((u - s) / max(H - belt, 1e-6), 0, 1)


def _paint_regions(shell: Mesh, xs: np.ndarray, t: dict, k: dict, n_ring: int) -> None:
    """Assign glass and trim to the loft's faces in place (the face order of :func:`loft`)."""
    _, glass = resolve_ids("car", "car_glass")
    _, trim = resolve_ids("car", "car_trim")
    n_gap = len(xs) - 1
    f = np.arange(2 * n_ring * n_gap)
    gap, edge = f // (2 * n_ring), (f % (2 * n_ring)) % n_ring
    xm = 0.5 * (xs[gap] + xs[gap + 1])
    # ring edges (right side, then mirrored on the left): 0 bottom->rocker, 1 rocker->mid,
    # 2 mid->shoulder, 3 shoulder->z4, 4 z4->roof edge, 5 roof edge->top, 6 top->crown;
    # 7..13 the same on the left in reverse; 14 the underside
    assert n_ring == 15
    side_rows = np.isin(edge, [3, 4, 9, 10])
    top_rows = np.isin(edge, [6, 7])
    side_glass = side_rows & (xm < k["glass_front"]) & (xm > k["glass_back"])
    pillar = np.zeros_like(side_glass)
    for xp in k["pillars"]:
        pillar |= side_glass & (np.abs(xm - xp) <= PILLAR_M / 2)
    side_glass &= ~pillar
    windscreen = top_rows & (xm < k["xa"] - 0.05) & (xm > k["xb"] + 0.03)
    rear = top_rows & (xm < k["xc"] - 0.03) & (xm > k["xd"] + 0.03)
    mats = shell.face_material
    mats[:len(f)][side_glass | windscreen | rear] = glass
    mats[:len(f)][np.isin(edge, [0, 13, 14]) | pillar] = trim     # sills, under-body, black B/C-pillars
    if t["tail"] == "bed":                    # the bed's tonneau cover
        mats[:len(f)][np.isin(edge, [5, 6, 7, 8]) & (xm < k["xd"] - 0.06)] = trim
