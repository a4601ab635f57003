"""Street furniture: lamp posts, traffic lights and traffic signs.

Poles are class ``pole`` (material ``pole_metal``); signal heads are class
``traffic_light`` and sign plates class ``traffic_sign``. Lamps and sign faces look
toward +x; the layout yaws the object to face the traffic it serves.
"""

from __future__ import annotations

import numpy as np

from assets_procedural.regulatory_signs import REGULATORY, SYMBOL_DEPTH_M, SYMBOL_MATERIAL, face_of
from generator.geometry import Mesh, box, cylinder, disc, merge, pose, prism, tube

X = np.array([1.0, 0.0, 0.0])


def lamp_post(rng: np.random.Generator, height: float = 7.0, arm: float = 1.5) -> Mesh:
    """A street lamp: tapered pole, an arm reaching toward +x and a luminaire under its end.

    Parameters
    ----------
    height : float
        Height of the luminaire's top above the ground, metres (3-15).
    arm : float
        Horizontal reach of the arm along +x, metres (0 for a post-top lantern).

    Returns
    -------
    Mesh
        Class ``pole``; anchor ``"lamp"`` (1, 3) 5 cm under the glass of the head.
    """
    if not (3.0 <= height <= 15.0 and 0.0 <= arm <= 5.0):
        raise ValueError(f"lamp_post needs height in [3, 15] and arm in [0, 5] m, got {height}, {arm}")
    r = float(rng.uniform(0.07, 0.1))
    head_len, head_w, head_h = float(rng.uniform(0.5, 0.75)), float(rng.uniform(0.25, 0.35)), 0.14
    parts = [cylinder(r * 1.9, 0.5, "pole", "pole_metal", 10),  # base plinth
             cylinder(r, height - 0.05, "pole", "pole_metal", 10, z0=0.0, radius_top=r * 0.6, caps=True)]
    if arm > 0:
        # the arm leaves the pole 0.7 m below its top, rises, and ends level with the top
        z0, z1 = height - 0.7, height - 0.1
        bend = np.array([0.35 * arm, 0.0, z1])
        parts.append(tube((0, 0, z0), bend, r * 0.5, "pole", "pole_metal", sections=6))
        parts.append(tube(bend, (arm + head_len * 0.3, 0, z1), r * 0.45, "pole", "pole_metal", sections=6))
        hx, hz = arm, z1 - 0.02
    else:
        hx, hz = 0.0, height - head_h / 2
        head_len = head_w = float(rng.uniform(0.35, 0.5))
    housing = box((head_len, head_w, head_h), "pole", "pole_metal", (hx, 0.0, hz))
    glass_z = hz - head_h / 2 - 0.02
    glass = box((head_len * 0.85, head_w * 0.85, 0.02), "pole", "lamp_glass", (hx, 0.0, glass_z + 0.01))
    parts += [housing, glass]
    out = merge(parts)
    out.anchors = {"lamp": np.array([[hx, 0.0, glass_z - 0.05]])}
    return out


def _signal_head(rng: np.random.Generator, centre: np.ndarray) -> tuple[list[Mesh], dict[str, np.ndarray]]:
    """A three-lamp signal head centred at ``centre`` facing +x, with back plate and visors."""
    d, w, h = 0.25, 0.34, 0.95
    lamp_r = float(rng.choice([0.1, 0.11]))
    cx, cy, cz = centre
    parts = [box((d, w, h), "traffic_light", "tl_housing", (cx, cy, cz)),
             box((0.02, w + 0.24, h + 0.24), "traffic_light", "tl_housing", (cx - d / 2 - 0.02, cy, cz))]
    anchors = {}
    front = cx + d / 2
    for k, name in enumerate(("tl_red", "tl_amber", "tl_green")):
        z = cz + (1 - k) * 0.3
        anchors[name] = np.array([[front + 0.02, cy, z]])
        parts.append(disc((front + 0.02, cy, z), X, lamp_r, "traffic_light", name, 12))
        # visor: a thin hood over the lamp, open at the bottom
        parts.append(box((0.16, 2 * lamp_r + 0.04, 0.015), "traffic_light", "tl_housing",
                         (front + 0.08, cy, z + lamp_r + 0.03)))
    return parts, anchors


def traffic_light(rng: np.random.Generator, arm: float = 0.0) -> Mesh:
    """A traffic signal: pole and a three-lamp head with the lamps facing +x.

    Parameters
    ----------
    arm : float
        0: the head sits on top of a ~3 m post. > 0: a ~6 m mast with a horizontal arm along
        +y, the head hanging under the arm ``arm`` metres from the pole (over the road,
        bottom at least 4.8 m above the ground).

    Returns
    -------
    Mesh
        Pole faces class ``pole``; head faces class ``traffic_light`` (``tl_housing`` and the
        lamp discs ``tl_red``/``tl_amber``/``tl_green``). Anchors ``"tl_red"``, ``"tl_amber"``,
        ``"tl_green"`` (1, 3) at the lamp centres.
    """
    if not 0.0 <= arm <= 12.0:
        raise ValueError(f"traffic_light arm must be in [0, 12] m, got {arm}")
    r = float(rng.uniform(0.06, 0.08))
    if arm > 0:
        mast = float(rng.uniform(6.2, 6.8))
        parts = [cylinder(r * 1.8, 0.4, "pole", "pole_metal", 10),
                 cylinder(r * 1.4, mast, "pole", "pole_metal", 10, radius_top=r)]
        za = mast - 0.25
        parts.append(tube((0, -r, za), (0, arm + 0.2, za), r * 0.6, "pole", "pole_metal", sections=8))
        parts.append(tube((0, 0, mast - 1.5), (0, 0.4 * arm, za), r * 0.3, "pole", "pole_metal", sections=6))
        centre = np.array([0.0, arm, za - 0.06 - 0.475 - 0.06])
        parts.append(box((0.05, 0.05, 0.1), "pole", "pole_metal", (0.0, arm, za - 0.06 - 0.05)))
    else:
        post = float(rng.uniform(2.6, 3.1))
        parts = [cylinder(r, post, "pole", "pole_metal", 10)]
        centre = np.array([0.0, 0.0, post + 0.475 - 0.1])
    head, anchors = _signal_head(rng, centre)
    out = merge(parts + head)
    out.anchors = anchors
    return out


def _sign_shape(shape: str, size: float) -> np.ndarray:
    """(k, 2) float: the plate outline in (y, z) around its centre, counter-clockwise seen from +x."""
    def ngon(k, radius, phase):
        a = phase + np.arange(k) * 2 * np.pi / k
        return radius * np.stack([np.cos(a), np.sin(a)], 1)

    table = {
        "circle": lambda: ngon(24, size / 2, 0.0),
        "triangle": lambda: ngon(3, size / np.sqrt(3), np.pi / 2) + [0, -size / np.sqrt(3) / 4],
        "square": lambda: ngon(4, size / np.sqrt(2), np.pi / 4),
        "octagon": lambda: ngon(8, size / 2 / np.cos(np.pi / 8), np.pi / 8),
        "diamond": lambda: ngon(4, size / 2, 0.0),
    }
    if shape not in table:
        raise ValueError(f"sign shape must be one of {sorted(table)}, got {shape!r}")
    return table[shape]()


SIGN_SIZES = {"circle": (0.6, 0.75), "triangle": (0.75, 0.9), "square": (0.6, 0.7),
              "octagon": (0.6, 0.75), "diamond": (0.8, 0.9)}


def traffic_sign(rng: np.random.Generator, shape: str = "circle") -> Mesh:
    """A road sign: a 2.2-2.8 m pole with a 2 cm plate whose face looks toward +x.

    Parameters
    ----------
    shape : {"circle", "triangle", "square", "octagon", "diamond", "one_way", "no_entry"}
        Plate outline; its size (0.5-0.9 m across) is drawn from the rng. ``one_way`` and
        ``no_entry`` are the regulatory signs of one-way streets
        (:mod:`assets_procedural.regulatory_signs`): a blue or red face with a white symbol on it.

    Returns
    -------
    Mesh
        Pole class ``pole``; plate class ``traffic_sign`` with the +x face ``sign_face``
        (retroreflective; ``sign_blue`` / ``sign_red`` under a ``sign_symbol`` plate for the
        regulatory shapes) and back and rim ``sign_back``.
    """
    symbols: list[np.ndarray] = []
    if shape in REGULATORY:
        outline, face, symbols = face_of(shape, rng)
    else:
        outline = _sign_shape(shape, 1.0) * float(rng.uniform(*SIGN_SIZES[shape]))
        face = "sign_face"
    pole_h = float(rng.uniform(2.2, 2.8))
    r = 0.03
    zc = pole_h - 0.1 - outline[:, 1].max()
    # prism extrudes along z with its top cap facing +z; the rotation maps +z -> +x and
    # prism coordinates (px, py) -> (y, z) = (py, -px), so feed (px, py) = (-z, y)
    to_plate = pose(r + 0.03, 0.0, zc, pitch=np.pi / 2)
    plate = prism(np.stack([-outline[:, 1], outline[:, 0]], 1), 0.0, 0.02, "traffic_sign", "sign_back",
                  top_material=face, bottom=True).transformed(to_plate)
    marks = [prism(np.stack([-o[:, 1], o[:, 0]], 1), 0.02, 0.02 + SYMBOL_DEPTH_M, "traffic_sign",
                   SYMBOL_MATERIAL).transformed(to_plate) for o in symbols]
    parts = [cylinder(r, pole_h, "pole", "pole_metal", 8), plate, *marks,
             box((0.04, 0.06, 0.04), "pole", "pole_metal", (r + 0.015, 0.0, zc + 0.6 * outline[:, 1].max())),
             box((0.04, 0.06, 0.04), "pole", "pole_metal", (r + 0.015, 0.0, zc + 0.6 * outline[:, 1].min()))]
    return merge(parts)
