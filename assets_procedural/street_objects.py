"""Street objects: benches, bins, bollards, bike racks, hydrants, advertising columns (class
``street_object``: SemanticKITTI other-object 99, Cityscapes static 4). Bus shelters are their
own class: :mod:`assets_procedural.shelters`.

Local frame: z up, origin on the ground at the centre of the footprint; the side that faces
the road is +x (a bench's sitter looks toward +x, a shelter is open toward +x, a hydrant's
pumper outlet points +x), like the faces of signs and the arms of lamp posts. Long objects
(benches, racks, shelters) run along y. Open objects keep their gaps: LiDAR beams pass between
the slats of a bench and through the hoops of a rack.
"""

from __future__ import annotations

import numpy as np

from assets_procedural.parts import centred, sweep
from generator.geometry import Mesh, box, cylinder, merge, pose

CLS = "street_object"



# -- bench --------------------------------------------------------------------------------------------

def bench(rng: np.random.Generator, length: float | None = None, backrest: bool | None = None) -> Mesh:
    """A park bench along y facing +x: two cast-iron side frames and wooden slats with gaps.

    Parameters
    ----------
    length : float, optional
        Metres (1.0-3.0); drawn (1.5-2.0) when omitted.
    backrest : bool, optional
        With a slatted backrest (drawn: 80 %).

    Returns
    -------
    Mesh
        Class ``street_object``; seat 0.42-0.46 m high, 0.45-0.7 m deep, 0.45-0.9 m high.
    """
    L = float(rng.uniform(1.5, 2.0)) if length is None else float(length)
    if not 1.0 <= L <= 3.0:
        raise ValueError(f"bench length must be in [1, 3] m, got {L}")
    backrest = bool(rng.random() < 0.8) if backrest is None else bool(backrest)
    seat_z, depth = float(rng.uniform(0.42, 0.46)), float(rng.uniform(0.42, 0.48))
    slat_w, slat_t = float(rng.uniform(0.06, 0.09)), 0.035
    gap = float(rng.uniform(0.015, 0.03))
    frame = str(rng.choice(["pole_metal", "fence_metal"]))
    parts: list[Mesh] = []
    frames_y = [-L / 2 + 0.12, L / 2 - 0.12] if L < 2.2 else [-L / 2 + 0.12, 0.0, L / 2 - 0.12]
    for y in frames_y:
        # front leg, rear leg, seat rail; the rear leg rises into the back support
        parts.append(
            box((0.05, 0.05, seat_z - slat_t), CLS, frame, (depth / 2 - 0.06, y, (seat_z - slat_t) / 2), bottom=False)
        )
        parts.append(
            box((0.05, 0.05, seat_z - slat_t), CLS, frame, (-depth / 2 + 0.06, y, (seat_z - slat_t) / 2), bottom=False)
        )
        parts.append(box((depth, 0.05, 0.05), CLS, frame, (0.0, y, seat_z - slat_t - 0.025)))
        if backrest:
            top = np.array([-depth / 2 - 0.12, y, seat_z + 0.42])
            parts.append(sweep(np.array([[-depth / 2 + 0.03, y, seat_z - slat_t - 0.03], top]), (0.025, 0.025), CLS,
                               frame, 4, binormal=(0, 1, 0)))
        if y in (frames_y[0], frames_y[-1]):   # armrests at the ends
            parts.append(sweep(np.array([[depth / 2 - 0.06, y, seat_z - slat_t], [depth / 2 - 0.02, y, seat_z + 0.2],
                                         [-depth / 2 + 0.05, y, seat_z + 0.22]]), 0.018, CLS, frame, 5))
    n = max(2, int((depth + gap) / (slat_w + gap)))
    for k in range(n):
        x = -depth / 2 + slat_w / 2 + k * (depth - slat_w) / (n - 1)
        parts.append(box((slat_w, L, slat_t), CLS, "fence_wood", (x, 0.0, seat_z - slat_t / 2)))
    if backrest:
        for k in range(3):
            f = 0.25 + 0.3 * k
            c = np.array([-depth / 2 + 0.03, 0.0, seat_z - slat_t - 0.03]) + f * np.array([-0.15, 0.0, 0.45])
            back = box((slat_t, L, slat_w + 0.02), CLS, "fence_wood")
            parts.append(back.transformed(pose(c[0] - 0.03, 0.0, c[2], pitch=-np.arctan2(0.15, 0.45))))
    return centred(merge(parts))


# -- bins ---------------------------------------------------------------------------------------------

def bin(rng: np.random.Generator, style: str | None = None) -> Mesh:  # noqa: A001 - the asset's name
    """A litter bin on a post, or a wheelie bin.

    Parameters
    ----------
    style : {"post", "wheelie"}, optional
        A round 50-70 l bin on a post with an open, dark mouth; or a 240 l wheelie bin with a
        lid, handle and two wheels at the back. Drawn when omitted.

    Returns
    -------
    Mesh
        Class ``street_object``; 0.9-1.15 m high.
    """
    style = str(rng.choice(["post", "wheelie"])) if style is None else style
    if style not in ("post", "wheelie"):
        raise ValueError(f"bin style must be 'post' or 'wheelie', got {style!r}")
    parts: list[Mesh] = []
    if style == "post":
        r, h = float(rng.uniform(0.17, 0.22)), float(rng.uniform(0.5, 0.6))
        top = float(rng.uniform(0.95, 1.05))
        parts.append(cylinder(0.03, top - 0.05, CLS, "pole_metal", 8).transformed(pose(x=-r - 0.04)))
        body = cylinder(r, h, CLS, "fence_metal", 14, z0=top - h, caps=True)
        parts.append(body)
        # the mouth: a dark disc just inside the rim, and the rim ring above it
        parts.append(cylinder(r * 0.92, 0.008, CLS, "rubber", 14, z0=top))
        parts.append(box((0.06, 0.06, 0.1), CLS, "pole_metal", (-r - 0.01, 0.0, top - 0.15)))
    else:
        w, d, h = float(rng.uniform(0.56, 0.6)), float(rng.uniform(0.72, 0.75)), float(rng.uniform(0.95, 1.02))
        # body tapers toward the bottom; the lid overhangs it
        bot = np.array([[-d / 2 + 0.05, -w / 2 + 0.04], [d / 2 - 0.05, -w / 2 + 0.04], [d / 2 - 0.05, w / 2 - 0.04],
                        [-d / 2 + 0.05, w / 2 - 0.04]])
        topo = np.array([[-d / 2, -w / 2], [d / 2, -w / 2], [d / 2, w / 2], [-d / 2, w / 2]])
        from generator.geometry import loft
        rings = np.array([np.c_[bot, np.full(4, 0.06)], np.c_[topo, np.full(4, h - 0.06)]])
        parts.append(loft(rings, CLS, "truck_paint"))
        parts.append(box((d + 0.04, w + 0.02, 0.05), CLS, "truck_paint", (0.02, 0.0, h - 0.035)))
        parts.append(sweep(np.array([[-d / 2 - 0.06, -w / 2 + 0.08, h - 0.12],
                                     [-d / 2 - 0.06, w / 2 - 0.08, h - 0.12]]),
                           0.016, CLS, "rubber", 6))
        for s in (1.0, -1.0):
            wheel = cylinder(0.1, 0.05, CLS, "rubber", 12).transformed(pose(-d / 2 + 0.02, s * (w / 2 - 0.08), 0.1,
                                                                            roll=-s * np.pi / 2))
            parts.append(wheel)
        parts.append(box((0.08, w - 0.2, 0.08), CLS, "tl_housing", (d / 2 - 0.1, 0.0, 0.04), bottom=False))
    return centred(merge(parts))


# -- bollards -----------------------------------------------------------------------------------------

def bollard(rng: np.random.Generator, style: str | None = None) -> Mesh:
    """A traffic bollard: a steel post with two retroreflective bands and a domed cap, or a
    squat concrete bollard with a chamfered top.

    Parameters
    ----------
    style : {"metal", "concrete"}, optional
        Drawn when omitted.

    Returns
    -------
    Mesh
        Class ``street_object``; metal 0.8-1.0 m x 0.1-0.2 m, concrete 0.5-0.7 m x 0.3-0.4 m.
    """
    style = str(rng.choice(["metal", "concrete"])) if style is None else style
    if style not in ("metal", "concrete"):
        raise ValueError(f"bollard style must be 'metal' or 'concrete', got {style!r}")
    if style == "metal":
        r, h = float(rng.uniform(0.05, 0.1)), float(rng.uniform(0.8, 0.95))
        parts = [cylinder(r, h, CLS, "pole_metal", 12, caps=False),
                 cylinder(r, 0.05, CLS, "pole_metal", 12, z0=h, radius_top=r * 0.55)]
        for z in (h - 0.2, h - 0.32):
            parts.append(cylinder(r + 0.003, 0.06, CLS, "sign_face", 12, z0=z, caps=False))
    else:
        r, h = float(rng.uniform(0.15, 0.2)), float(rng.uniform(0.5, 0.7))
        parts = [cylinder(r, h - 0.06, CLS, "curb_concrete", 14, caps=False),
                 cylinder(r, 0.06, CLS, "curb_concrete", 14, z0=h - 0.06, radius_top=r * 0.75)]
    return centred(merge(parts))


# -- bike racks ---------------------------------------------------------------------------------------

def bike_rack(rng: np.random.Generator, stands: int | None = None, style: str | None = None) -> Mesh:
    """A row of bike stands along y: Sheffield hoops (inverted U tubes in the x-z plane, a bike
    leans on each side) or a low grid rack with vertical wheel bars.

    Parameters
    ----------
    stands : int, optional
        Hoops (1-10) or wheel slots / 2 of the grid; drawn (2-5) when omitted.
    style : {"hoops", "grid"}, optional
        Drawn when omitted.

    Returns
    -------
    Mesh
        Class ``street_object`` (open: rays pass between the tubes); hoops 0.75-0.9 m high.
    """
    style = str(rng.choice(["hoops", "grid"])) if style is None else style
    if style not in ("hoops", "grid"):
        raise ValueError(f"bike_rack style must be 'hoops' or 'grid', got {style!r}")
    n = int(rng.integers(2, 6)) if stands is None else int(stands)
    if not 1 <= n <= 10:
        raise ValueError(f"bike_rack stands must be in [1, 10], got {n}")
    parts: list[Mesh] = []
    if style == "hoops":
        w, h, rb = float(rng.uniform(0.6, 0.8)), float(rng.uniform(0.75, 0.9)), 0.15
        pitch = float(rng.uniform(0.8, 1.0))
        for k in range(n):
            y = (k - (n - 1) / 2) * pitch
            left = np.stack([-w / 2 + rb + rb * np.cos(np.linspace(np.pi, np.pi / 2, 4)), np.full(4, y),
                             h - rb + rb * np.sin(np.linspace(np.pi, np.pi / 2, 4))], 1)
            right = np.stack([w / 2 - rb + rb * np.cos(np.linspace(np.pi / 2, 0.0, 4)), np.full(4, y),
                              h - rb + rb * np.sin(np.linspace(np.pi / 2, 0.0, 4))], 1)
            path = np.concatenate([[[-w / 2, y, 0.0]], left, right, [[w / 2, y, 0.0]]])
            parts.append(sweep(path, 0.024, CLS, "pole_metal", 8, caps=False))
    else:
        slots = 2 * n
        pitch = float(rng.uniform(0.35, 0.45))
        span = (slots - 1) * pitch
        h = float(rng.uniform(0.35, 0.45))
        for x in (-0.25, 0.25):
            parts.append(sweep(np.array([[x, -span / 2 - 0.1, h], [x, span / 2 + 0.1, h]]), 0.02, CLS, "pole_metal", 6))
            parts.append(
                sweep(np.array([[x, -span / 2 - 0.1, 0.03], [x, span / 2 + 0.1, 0.03]]), 0.02, CLS, "pole_metal", 6)
            )
        for y in (-span / 2 - 0.1, span / 2 + 0.1):
            for x in (-0.25, 0.25):
                parts.append(cylinder(0.02, h + 0.02, CLS, "pole_metal", 6).transformed(pose(x, y)))
        for k in range(slots):
            y = (k - (slots - 1) / 2) * pitch
            # a wheel slot: two bent bars, 5 cm apart, rising from the bottom rail over the top rail
            for dy in (-0.03, 0.03):
                parts.append(sweep(np.array([[-0.35, y + dy, 0.03], [-0.25, y + dy, h], [0.25, y + dy, h],
                                             [0.35, y + dy, 0.03]]),
                                   0.008, CLS, "pole_metal", 4, caps=False))
    return centred(merge(parts))


# -- hydrant ------------------------------------------------------------------------------------------

def hydrant(rng: np.random.Generator, style: str | None = None) -> Mesh:
    """A pillar fire hydrant: a European pillar (tall, slim, two side outlets) or a North
    American one (short, a domed bonnet, two hose nozzles and a pumper nozzle toward +x).

    Parameters
    ----------
    style : {"pillar", "us"}, optional
        Drawn when omitted.

    Returns
    -------
    Mesh
        Class ``street_object``, painted ``truck_paint`` (tinted by the object's colour: give it a
        red or yellow ``color`` attribute when placing), outlets and caps ``chrome``.
    """
    style = str(rng.choice(["pillar", "us"])) if style is None else style
    if style not in ("pillar", "us"):
        raise ValueError(f"hydrant style must be 'pillar' or 'us', got {style!r}")
    parts: list[Mesh] = []
    if style == "pillar":
        r, h = float(rng.uniform(0.09, 0.12)), float(rng.uniform(0.85, 1.05))
        parts.append(cylinder(r * 1.5, 0.08, CLS, "truck_paint", 12))
        parts.append(cylinder(r, h - 0.18, CLS, "truck_paint", 12, z0=0.08))
        parts.append(cylinder(r * 1.15, 0.06, CLS, "truck_paint", 12, z0=h - 0.1))
        parts.append(cylinder(r * 1.0, 0.06, CLS, "chrome", 12, z0=h - 0.04, radius_top=r * 0.3))
        for s in (1.0, -1.0):
            zo = h - 0.35
            parts.append(
                cylinder(0.045, 0.09, CLS, "chrome", 10).transformed(pose(0.0, s * r * 0.7, zo, roll=-s * np.pi / 2))
            )
    else:
        r, h = float(rng.uniform(0.11, 0.13)), float(rng.uniform(0.6, 0.75))
        parts.append(cylinder(r * 1.6, 0.05, CLS, "truck_paint", 12))
        parts.append(cylinder(r, h - 0.2, CLS, "truck_paint", 12, z0=0.05))
        parts.append(cylinder(r * 1.2, 0.05, CLS, "truck_paint", 12, z0=h - 0.15))
        parts.append(cylinder(r * 1.05, 0.1, CLS, "truck_paint", 12, z0=h - 0.1, radius_top=r * 0.45))
        parts.append(cylinder(0.025, 0.04, CLS, "chrome", 6, z0=h, radius_top=0.02).transformed(pose(z=-0.005)))
        zo = h - 0.32
        for s in (1.0, -1.0):
            parts.append(
                cylinder(0.04, 0.08, CLS, "chrome", 10).transformed(pose(0.0, s * r * 0.8, zo, roll=-s * np.pi / 2))
            )
        parts.append(
            cylinder(0.06, 0.09, CLS, "chrome", 10).transformed(pose(r * 0.8, 0.0, zo - 0.05, pitch=np.pi / 2))
        )
    return centred(merge(parts))


# -- advertising column -------------------------------------------------------------------------------

def advertising_column(rng: np.random.Generator, height: float | None = None) -> Mesh:
    """An advertising column (Litfass column): a plinth, a poster-covered drum, a crown ring and
    a shallow cone roof with a finial.

    Parameters
    ----------
    height : float, optional
        Top of the finial, metres (2.5-4.5); drawn (3.0-3.8) when omitted.

    Returns
    -------
    Mesh
        Class ``street_object``; 1.1-1.6 m across (crown).
    """
    H = float(rng.uniform(3.0, 3.8)) if height is None else float(height)
    if not 2.5 <= H <= 4.5:
        raise ValueError(f"advertising_column height must be in [2.5, 4.5] m, got {H}")
    r = float(rng.uniform(0.55, 0.7))
    seg = 20
    plinth = 0.3
    drum_top = H - 0.55
    parts = [cylinder(r + 0.05, plinth, CLS, "facade_concrete", seg, caps=False),
             cylinder(r, drum_top - plinth, CLS, "facade_plaster", seg, z0=plinth, caps=False),
             cylinder(r + 0.05, 0.04, CLS, "facade_concrete", seg, z0=plinth - 0.04, radius_top=r, caps=False),
             cylinder(r + 0.12, 0.18, CLS, "pole_metal", seg, z0=drum_top),
             cylinder(r + 0.08, 0.3, CLS, "pole_metal", seg, z0=drum_top + 0.18, radius_top=0.12),
             cylinder(0.04, 0.12, CLS, "pole_metal", 6, z0=drum_top + 0.48, radius_top=0.008)]
    # the top of the plinth ring closes the gap between plinth and drum
    return centred(merge(parts))
