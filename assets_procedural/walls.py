"""Free-standing walls along x: garden walls, retaining walls and noise barriers.

Like fences they run from ``-length / 2`` to ``+length / 2`` centred on y = 0, the face a road
would see at -y. Every face is class ``wall`` (SemanticKITTI fence 51 - "small walls" are
separators - and Cityscapes wall 12; the reasoning is in ``classes.yaml``). Walls are solid:
no label proxy.
"""

from __future__ import annotations

import numpy as np

from generator.geometry import Mesh, box, merge, pose, prism

CLS = "wall"
STYLES = ("garden", "retaining", "noise")


def _posts(length: float, spacing: float, width: float) -> np.ndarray:
    """(k,) post centres from -length/2 to +length/2 with the end posts flush with the ends."""
    half = length / 2 - width / 2
    n = max(1, int(np.ceil(2 * half / spacing)))
    return np.linspace(-half, half, n + 1)


def _garden(rng: np.random.Generator, length: float, height: float) -> Mesh:
    """Brick or rendered masonry, 24 cm thick, piers every ~3 m, an overhanging coping."""
    mat = str(rng.choice(["facade_brick", "facade_plaster"]))
    t = float(rng.choice([0.24, 0.3]))
    pier_w = t + 0.12
    coping_h = 0.06
    body_h = height - coping_h
    parts = [box((length - 2 * 0.01, t, body_h), CLS, mat, (0.0, 0.0, body_h / 2), bottom=False)]
    piers = _posts(length, float(rng.uniform(2.6, 3.4)), pier_w) if length > 1.5 else np.zeros(0)
    for x in piers:
        parts.append(box((pier_w, pier_w, height + 0.08), CLS, mat, (x, 0.0, (height + 0.08) / 2), bottom=False))
        parts.append(box((pier_w + 0.06, pier_w + 0.06, 0.06), CLS, "curb_concrete", (x, 0.0, height + 0.11)))
    parts.append(box((length, t + 0.06, coping_h), CLS, "curb_concrete", (0.0, 0.0, height - coping_h / 2)))
    return merge(parts)


def _retaining(rng: np.random.Generator, length: float, height: float) -> Mesh:
    """Cast concrete with a battered back: thick at the foot, thinner at the top; plain coping."""
    base_t, top_t = float(rng.uniform(0.4, 0.6)), float(rng.uniform(0.25, 0.32))
    # cross-section in (y, z): vertical face at y = -base_t/2 (the street side), battered back
    sec = np.array([[-base_t / 2, 0.0], [base_t / 2, 0.0], [-base_t / 2 + top_t, height], [-base_t / 2, height]])
    # prism extrudes along z: map (px, py, pz) -> (x, y, z) = (pz, px, py)
    along_x = np.array([[0.0, 0.0, 1.0, 0.0], [1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
    body = prism(sec, -length / 2, length / 2, CLS, "facade_concrete", bottom=True).transformed(along_x)
    parts = [body]
    # expansion joints every ~6 m: shallow dark vertical strips on the street face
    for x in _posts(length, 6.0, 0.02)[1:-1] if length > 6.5 else []:
        parts.append(box((0.02, 0.01, height - 0.1), CLS, "rubber", (x, -base_t / 2 - 0.005, height / 2 - 0.05)))
    parts.append(
        box((length, top_t + 0.04, 0.05), CLS, "curb_concrete", (0.0, -base_t / 2 + top_t / 2, height + 0.025))
    )
    # weep holes near the foot
    for x in np.arange(-length / 2 + 1.0, length / 2 - 0.5, 2.0):
        parts.append(box((0.08, 0.01, 0.08), CLS, "rubber", (x, -base_t / 2 - 0.005, 0.3)))
    return merge(parts)


def _noise(rng: np.random.Generator, length: float, height: float) -> Mesh:
    """A noise barrier: concrete plinth, steel H-posts every 4-5 m, stacked panels between them."""
    panel_mat = str(rng.choice(["fence_wood", "facade_concrete", "fence_metal", "car_glass"]))
    post_w, post_d = 0.16, 0.2
    plinth_h = float(rng.uniform(0.4, 0.6))
    posts = _posts(length, float(rng.uniform(4.0, 5.0)), post_w)
    parts = [box((length, 0.2, plinth_h), CLS, "facade_concrete", (0.0, 0.0, plinth_h / 2), bottom=False)]
    for x in posts:
        # H-profile: two flanges across x, a web along y
        for dx in (-post_w / 2 + 0.01, post_w / 2 - 0.01):
            parts.append(box((0.02, post_d, height + 0.05), CLS, "pole_metal", (x + dx, 0.0, (height + 0.05) / 2),
                             bottom=False))
        parts.append(box((post_w - 0.04, 0.015, height + 0.05), CLS, "pole_metal", (x, 0.0, (height + 0.05) / 2),
                         bottom=False))
    elem_h = 0.5
    n = max(1, int(round((height - plinth_h) / elem_h)))
    zs = np.linspace(plinth_h, height, n + 1)
    for xa, xb in zip(posts[:-1], posts[1:], strict=False):
        xa, xb = xa + post_w / 2 - 0.02, xb - post_w / 2 + 0.02
        for k, (z0, z1) in enumerate(zip(zs[:-1], zs[1:], strict=False)):
            # panels alternate a few millimetres in depth so each element reads as its own
            dy = 0.004 * (k % 2)
            t = 0.12 if panel_mat != "car_glass" else 0.03
            parts.append(box((xb - xa, t, z1 - z0 - 0.004), CLS, panel_mat, ((xa + xb) / 2, dy, (z0 + z1) / 2)))
    if panel_mat == "car_glass":
        # bird-protection: a few narrow vertical dark stripes on the glass, proud of it
        for xa, xb in zip(posts[:-1], posts[1:], strict=False):
            for x in np.linspace(xa + 0.3, xb - 0.3, 5):
                parts.append(box((0.02, 0.005, height - plinth_h - 0.1), CLS, "rubber",
                                 (x, -0.03 / 2 - 0.0125, (height + plinth_h) / 2)))
    return merge(parts)


BUILDERS = {"garden": _garden, "retaining": _retaining, "noise": _noise}
HEIGHTS = {"garden": (1.0, 2.0), "retaining": (0.8, 2.5), "noise": (2.5, 4.5)}


def wall(rng: np.random.Generator, length: float, height: float | None = None, style: str | None = None) -> Mesh:
    """A free-standing wall along x from ``-length / 2`` to ``+length / 2``, centred on y = 0.

    Parameters
    ----------
    length : float
        Metres (>= 0.5).
    height : float, optional
        Metres (0.5-6); drawn from the style's range (garden 1-2, retaining 0.8-2.5, noise
        2.5-4.5) when omitted.
    style : {"garden", "retaining", "noise"}, optional
        Brick/rendered garden wall with piers and coping; battered concrete retaining wall with
        joints and weep holes; noise barrier of posts and stacked wood, concrete, aluminium or
        glass panels on a plinth. Drawn when omitted.

    Returns
    -------
    Mesh
        Class ``wall``; 0.2-0.6 m thick.
    """
    style = str(rng.choice(STYLES)) if style is None else style
    if style not in BUILDERS:
        raise ValueError(f"wall style must be one of {list(STYLES)}, got {style!r}")
    height = float(rng.uniform(*HEIGHTS[style])) if height is None else float(height)
    if not (length >= 0.5 and 0.5 <= height <= 6.0):
        raise ValueError(f"wall needs length >= 0.5 and height in [0.5, 6] m, got {length}, {height}")
    out = BUILDERS[style](rng, float(length), height)
    lo, hi = out.bounds()
    return out.transformed(pose(y=-(lo[1] + hi[1]) / 2, z=-lo[2]))
