"""Bicycles: city, road and mountain bikes, parked (upright or leaning) or under a rider.

Local frame: +x forward, z up, origin on the ground at the centre of the vehicle's footprint
(bounding box in x and y); both tyres touch z = 0. Every face is class ``bicycle``.

A bicycle is open where a real one is: spoked wheels (tyre and rim rings, thin spokes), a tube
frame, bars and saddle, so a LiDAR beam passes through the wheels and between the tubes.
Riders: :mod:`assets_procedural.riders`; motorcycles: :mod:`assets_procedural.motorcycles`.
"""

from __future__ import annotations

import numpy as np

from assets_procedural.parts import centred, ring_plate, spoked_wheel, sweep
from generator.geometry import Mesh, box, loft, merge, pose, tube

BIKE_STYLES = ("city", "sport", "mtb")


#: bicycle style -> ranges (low, high): wheel outer radius, tyre section radius, wheelbase, seat and
#: head angles (deg), seat-tube length, saddle height above the bottom bracket, bar width
BIKE = {
    "city": dict(R=(0.345, 0.355), tyre=(0.018, 0.021), wb=(1.08, 1.15), sa=(70.0, 72.0), ha=(68.0, 70.0),
                 st=(0.46, 0.54), sh=(0.64, 0.78), bar=(0.56, 0.62), tube=0.016),
    "sport": dict(R=(0.334, 0.340), tyre=(0.012, 0.014), wb=(0.97, 1.01), sa=(73.0, 74.0), ha=(72.0, 73.5),
                  st=(0.50, 0.58), sh=(0.66, 0.80), bar=(0.40, 0.44), tube=0.017),
    "mtb": dict(R=(0.355, 0.37), tyre=(0.026, 0.030), wb=(1.12, 1.20), sa=(73.0, 75.0), ha=(65.0, 67.0),
                st=(0.40, 0.48), sh=(0.64, 0.78), bar=(0.72, 0.78), tube=0.022),
}


def _draw(rng: np.random.Generator, spec: dict) -> dict:
    return {k: float(rng.uniform(*v)) if isinstance(v, tuple) else v for k, v in spec.items()}


def _style_params(rng: np.random.Generator, style: str | None, table: dict, what: str) -> tuple[str, dict]:
    """The style (drawn when None, checked otherwise) and its parameters drawn from ``table[style]``."""
    styles = tuple(table)
    if style is None:
        style = str(rng.choice(styles))
    if style not in table:
        raise ValueError(f"{what} style must be one of {styles}, got {style!r}")
    return style, _draw(rng, table[style])


def _xz(angle_deg: float) -> np.ndarray:
    """Unit vector in the x-z plane pointing up and back at ``angle_deg`` from the ground (frame tubes)."""
    a = np.radians(angle_deg)
    return np.array([-np.cos(a), 0.0, np.sin(a)])


def _bezier(p0, p1, p2, n: int = 5) -> np.ndarray:
    t = np.linspace(0, 1, n)[:, None]
    return (1 - t) ** 2 * np.asarray(p0) + 2 * t * (1 - t) * np.asarray(p1) + t ** 2 * np.asarray(p2)


def _saddle(top_centre: np.ndarray, cls: str, length: float = 0.27, width: float = 0.15) -> Mesh:
    """A saddle (closed loft, ``rubber``) whose top centre is ``top_centre``; the nose points +x."""
    xs = np.array([-0.5, -0.35, -0.05, 0.25, 0.5]) * length
    half_w = np.array([0.35, 0.5, 0.42, 0.16, 0.1]) * width
    h = 0.05
    rings = []
    a = np.linspace(0, 2 * np.pi, 8, endpoint=False)
    for x, w in zip(xs, half_w, strict=False):
        rings.append(np.stack([np.full(8, x), w * np.cos(a), -h / 2 + h / 2 * np.sin(a)], 1))
    m = loft(np.array(rings), cls, "rubber")
    return m.transformed(pose(*(top_centre + np.array([0.0, 0.0, 0.0]))))


# -- bicycle -----------------------------------------------------------------------------------

def _bicycle_parts(rng: np.random.Generator, style: str | None) -> tuple[list[Mesh], dict]:
    """Bicycle meshes in a raw frame (rear axle at x = 0, wheels on z = 0) and its contact points."""
    style, p = _style_params(rng, style, BIKE, "bicycle")
    cls = "bicycle"
    R, wb, tr = p["R"], p["wb"], p["tube"]
    crank_phase = float(rng.uniform(0, 2 * np.pi))
    frame_mat = "pole_metal" if rng.random() < 0.25 else "car_paint"
    ra = np.array([0.0, 0.0, R])
    fa = np.array([wb, 0.0, R])
    drop = 0.07 if style != "mtb" else 0.04
    cs = 0.45 if style == "city" else (0.41 if style == "sport" else 0.44)
    bb = np.array([np.sqrt(cs ** 2 - drop ** 2), 0.0, R - drop])
    st_dir, hs_dir = _xz(p["sa"]), _xz(p["ha"])
    st_top = bb + p["st"] * st_dir
    saddle_top = bb + p["sh"] * st_dir + np.array([0.0, 0.0, 0.035])
    # steering axis: the front axle sits ``rake`` ahead of it; the fork crown 0.40 m up the axis
    rake = 0.045
    ahead = np.array([-hs_dir[2], 0.0, -hs_dir[0]])          # unit, perpendicular to the axis, forward
    if ahead[0] < 0:
        ahead = -ahead
    crown = fa - rake * ahead + (0.40 if style != "mtb" else 0.50) * hs_dir
    ht_len = {"city": 0.2, "sport": 0.15, "mtb": 0.12}[style]
    ht_top = crown + ht_len * hs_dir
    parts: list[Mesh] = []
    y = np.array([0.0, 1.0, 0.0])
    # wheels
    n_spokes = int(rng.choice([16, 18, 20])) if style != "mtb" else 16
    for c in (ra, fa):
        parts.append(spoked_wheel(c, R, p["tyre"], cls, n_spokes=n_spokes))
    # frame
    ttop_seat = bb + (0.93 if style != "mtb" else 0.78) * p["st"] * st_dir
    parts.append(tube(bb, st_top, tr, cls, frame_mat, sections=6))
    parts.append(tube(crown - 0.01 * hs_dir, ht_top + 0.01 * hs_dir, tr * 1.3, cls, frame_mat, sections=6))
    if style == "city":   # step-through: one bent down tube from the head tube to the bottom bracket
        mid = bb + np.array([0.22, 0.0, 0.02])
        parts.append(sweep(_bezier(ht_top - 0.05 * hs_dir, mid, bb + [0.03, 0, 0.03]), tr * 1.35, cls, frame_mat, 6))
        parts.append(sweep(_bezier(crown + 0.02 * hs_dir, mid + [0.05, 0, -0.08], bb + [0.06, 0, 0.0]), tr, cls,
                           frame_mat, 8))
    else:
        parts.append(tube(ttop_seat, ht_top - 0.02 * hs_dir, tr, cls, frame_mat, sections=6))
        parts.append(tube(bb, crown + 0.03 * hs_dir, tr * 1.25, cls, frame_mat, sections=6))
    for side in (1.0, -1.0):
        hub = ra + side * np.array([0.0, 0.06, 0.0])
        parts.append(tube(hub, bb + side * np.array([0.0, 0.025, 0.0]), tr * 0.6, cls, frame_mat, sections=6))
        parts.append(tube(hub, st_top - 0.04 * st_dir + side * np.array([0.0, 0.015, 0.0]), tr * 0.55, cls, frame_mat,
                          sections=6))
        parts.append(tube(fa + side * np.array([0.0, 0.055, 0.0]), crown + side * np.array([0.0, 0.04, 0.0]),
                          tr * (0.7 if style != "mtb" else 1.1), cls, frame_mat, sections=6))
    parts.append(box((0.05, 0.11, 0.03), cls, frame_mat, tuple(crown - 0.015 * hs_dir)))
    parts.append(tube(bb - 0.04 * y, bb + 0.04 * y, 0.022, cls, frame_mat, sections=6))
    # seat post and saddle
    parts.append(tube(st_top, saddle_top - np.array([0.02, 0.0, 0.065]), 0.0135, cls, "chrome", sections=6))
    saddle_top = saddle_top - np.array([0.02, 0.0, 0.025])      # the saddle's real top centre
    parts.append(_saddle(saddle_top, cls))
    # stem and bars
    stem_top = ht_top + 0.05 * hs_dir
    if style == "city":
        clamp = stem_top + np.array([0.03, 0.0, 0.08])
        grip_x, grip_z = clamp[0] - 0.17, clamp[2] + 0.03
        bar_path = lambda s: [  # noqa: E731
            np.array([grip_x, s * p["bar"] / 2, grip_z]), np.array([grip_x + 0.07, s * p["bar"] / 2 * 0.8, grip_z]),
            np.array([clamp[0] - 0.02, s * 0.12, clamp[2] + 0.01]), np.array([clamp[0], 0.0, clamp[2]])]
    elif style == "sport":
        clamp = stem_top + np.array([0.10, 0.0, -0.01])
        grip_x, grip_z = clamp[0] + 0.02, clamp[2] - 0.01
        bar_path = lambda s: [  # noqa: E731
            np.array([grip_x - 0.03, s * p["bar"] / 2, grip_z - 0.11]),
            np.array([grip_x + 0.06, s * p["bar"] / 2, grip_z - 0.08]),
            np.array([grip_x + 0.08, s * p["bar"] / 2, grip_z - 0.02]),
            np.array([grip_x, s * p["bar"] / 2, grip_z]),
            np.array([clamp[0], 0.0, clamp[2]]),
        ]
    else:
        clamp = stem_top + np.array([0.06, 0.0, 0.0])
        grip_x, grip_z = clamp[0] - 0.01, clamp[2] + 0.015
        bar_path = lambda s: [np.array([grip_x, s * p["bar"] / 2, grip_z]), np.array([clamp[0], 0.0, clamp[2]])]  # noqa: E731
    parts.append(tube(ht_top, stem_top, 0.015, cls, "pole_metal", sections=6))
    parts.append(tube(stem_top, clamp, 0.015, cls, "pole_metal", sections=6))
    grips = []                                               # right (-y) first, then left
    for s in (-1.0, 1.0):
        path = np.array(bar_path(s))
        parts.append(sweep(path, 0.011, cls, "pole_metal", 6))
        g = path[0] if style != "sport" else path[3]
        inward = (path[1] - path[0]) if style != "sport" else (path[4] - path[3])
        inward = inward / np.linalg.norm(inward)
        if style != "sport":
            parts.append(tube(g - 0.01 * inward, g + 0.11 * inward, 0.016, cls, "rubber", sections=6))
            grips.append(g + 0.05 * inward)
        else:
            grips.append(g + 0.06 * inward)
    # drive train: chainring (drive side = right = -y), cranks, pedals
    parts.append(ring_plate(bb - 0.055 * y, y, 0.055, 0.10, cls, "chrome", 12))
    pedals = []
    for s, phase in ((-1.0, crank_phase), (1.0, crank_phase + np.pi)):
        d = np.array([np.cos(phase), 0.0, np.sin(phase)])
        end = bb + 0.17 * d + s * np.array([0.0, 0.085, 0.0])
        parts.append(tube(bb + s * np.array([0.0, 0.07, 0.0]), end, 0.012, cls, "pole_metal", sections=4))
        pedal = end + s * np.array([0.0, 0.055, 0.0])
        parts.append(box((0.1, 0.09, 0.022), cls, "rubber", tuple(pedal)))
        pedals.append(pedal)
    parts.append(tube(bb - 0.055 * y + np.array([0.0, 0.0, 0.1]), ra + np.array([0.0, -0.055, 0.05]), 0.004, cls,
                      "chrome", sections=4, caps=False))
    parts.append(tube(bb - 0.055 * y - np.array([0.0, 0.0, 0.1]), ra + np.array([0.0, -0.055, -0.05]), 0.004, cls,
                      "chrome", sections=4, caps=False))
    if style == "city":
        # mudguards over both wheels, a rear rack, a lamp on the fork crown
        for c, a0, a1 in ((ra, np.radians(15), np.radians(175)), (fa, np.radians(10), np.radians(150))):
            path = c + (R + 0.025) * np.stack([np.cos(np.linspace(a0, a1, 8)), np.zeros(8),
                                                 np.sin(np.linspace(a0, a1, 8))], 1)
            parts.append(sweep(path, (0.006, 0.028), cls, frame_mat, 4, binormal=(0, 1, 0)))
        rack_z = R + 0.08
        for side in (1.0, -1.0):
            parts.append(tube(ra + side * np.array([0.0, 0.07, 0.0]), np.array([-0.12, side * 0.07, rack_z]), 0.006,
                              cls, "pole_metal", sections=4))
            parts.append(tube(np.array([-0.14, side * 0.07, rack_z]), np.array([0.22, side * 0.07, rack_z]), 0.007,
                              cls, "pole_metal", sections=4))
        parts.append(
            tube(np.array([0.2, -0.08, rack_z]), np.array([0.2, 0.08, rack_z]), 0.007, cls, "pole_metal", sections=4)
        )
        parts.append(box((0.04, 0.07, 0.05), cls, "headlight", tuple(crown + ahead * 0.06 + np.array([0, 0, 0.02]))))
        parts.append(box((0.03, 0.06, 0.03), cls, "taillight", (-0.16, 0.0, rack_z - 0.01)))
    info = dict(style=style, R=R, saddle=saddle_top, grips=grips, pedals=pedals, bb=bb, crank_phase=crank_phase,
                sh=p["sh"])
    return parts, info


def bicycle(rng: np.random.Generator, style: str | None = None, lean_deg: float = 0.0) -> Mesh:
    """A bicycle (no rider).

    Parameters
    ----------
    rng : numpy.random.Generator
        Sizes, frame colour material, spoke count and crank phase are drawn from it.
    style : {"city", "sport", "mtb"}, optional
        Step-through city bike with mudguards, rack and lamps; road bike with drop bars; mountain
        bike with fat tyres, suspension-like fork and wide bars. Drawn when omitted.
    lean_deg : float
        Roll to the left (+) or right (-) about the contact line, degrees (a bike on its
        kickstand leans 5-10 degrees; 0 in a rack).

    Returns
    -------
    Mesh
        Class ``bicycle``: 1.6-2.0 m long, 0.4-0.8 m wide (bars), 0.95-1.25 m high; open spoked
        wheels touching z = 0.
    """
    parts, info = _bicycle_parts(rng, style)
    m = merge(parts)
    m.anchors = contact_anchors(info)
    if lean_deg:
        m = m.transformed(pose(roll=np.radians(lean_deg)))
    return centred(m)


def contact_anchors(info: dict) -> dict[str, np.ndarray]:
    """Where a rider touches the vehicle: ``"saddle"`` (1, 3) top centre of the saddle or seat,
    ``"grips"`` (2, 3) and ``"footrests"`` (2, 3) (pedals or pegs), right (-y) first."""
    feet = info["pedals"] if "pedals" in info else info["feet"]
    return {"saddle": np.asarray(info["saddle"], float)[None], "grips": np.array(info["grips"], float),
            "footrests": np.array(feet, float)}

