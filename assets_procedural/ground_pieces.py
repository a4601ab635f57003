"""Ground pieces labelled ``other_ground``: traffic islands, median strips, driveway aprons, verge
crossings and gravel patches (SemanticKITTI other-ground 49, Cityscapes ground 6).

Local frame: z up, the bottom at z = 0 (the layout lays them on the road or terrain surface),
origin at the centre of the footprint. Islands and medians run along x and are raised like a
kerb (their kerb faces belong to the island: ``curb_concrete`` material, class
``other_ground``); a driveway apron ramps up from its road edge at +x to kerb height at -x;
a gravel patch is a thin irregular slab.
"""

from __future__ import annotations

import numpy as np

from assets_procedural.parts import centred
from generator.geometry import Mesh, face_normals, merge, prism, resolve_ids, triangulate

CLS = "other_ground"


def _stadium(length: float, width: float, taper: float, k: int = 8) -> np.ndarray:
    """(n, 2) counter-clockwise outline along x: a round nose at +x, the -x end narrowed to
    ``taper`` times the width (1 = both ends round)."""
    r1 = width / 2
    r0 = max(0.2, width / 2 * taper)
    x1, x0 = length / 2 - r1, -length / 2 + r0
    a1 = np.linspace(-np.pi / 2, np.pi / 2, k)
    a0 = np.linspace(np.pi / 2, 3 * np.pi / 2, k)
    front = np.stack([x1 + r1 * np.cos(a1), r1 * np.sin(a1)], 1)
    back = np.stack([x0 + r0 * np.cos(a0), r0 * np.sin(a0)], 1)
    return np.concatenate([front, back])


def _raised(outline: np.ndarray, height: float, top: str, kerb_w: float = 0.12) -> Mesh:
    """A kerbed island: kerb-stone sides, a kerb band ``kerb_w`` wide along the edge and a paved
    top inside it, all at one height (no overlapping faces) and all class ``other_ground``."""
    body = prism(outline, 0.0, height, CLS, "curb_concrete")
    sides = body.select(np.abs(face_normals(body)[:, 2]) < 0.5)
    inner = _inset(outline, kerb_w)
    c, m = resolve_ids(CLS, top)
    paved = Mesh(np.c_[inner, np.full(len(inner), height)], triangulate(inner), c, m)
    return merge([sides, _ring_band(outline, inner, height), paved])


def _inset(outline: np.ndarray, d: float) -> np.ndarray:
    """The outline moved inward by ``d`` along the averaged edge normals (convex-ish outlines)."""
    p = outline
    e_prev = p - np.roll(p, 1, 0)
    e_next = np.roll(p, -1, 0) - p
    n_prev = np.stack([e_prev[:, 1], -e_prev[:, 0]], 1)
    n_next = np.stack([e_next[:, 1], -e_next[:, 0]], 1)
    n = n_prev / np.linalg.norm(n_prev, axis=1, keepdims=True) + n_next / np.linalg.norm(n_next, axis=1, keepdims=True)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    return p - d * n          # outward normals of a counter-clockwise outline point right of the edge


def _ring_band(outer: np.ndarray, inner: np.ndarray, z: float) -> Mesh:
    """Upward-facing quads between two outlines at height ``z`` (the kerb's top band)."""
    k = len(outer)
    v = np.concatenate([np.c_[outer, np.full(k, z)], np.c_[inner, np.full(k, z)]])
    i = np.arange(k)
    j = (i + 1) % k
    faces = np.concatenate([np.stack([i, j, k + j], 1), np.stack([i, k + j, k + i], 1)])
    c, m = resolve_ids(CLS, "curb_concrete")
    return Mesh(v, faces, c, m)


def traffic_island(rng: np.random.Generator, length: float | None = None, width: float | None = None,
                   shape: str | None = None) -> Mesh:
    """A raised traffic island along x: a kerb ring around a paved top.

    Parameters
    ----------
    length, width : float, optional
        Metres (2-20 x 1-4); drawn (3-8 x 1.2-2.5) when omitted.
    shape : {"teardrop", "stadium"}, optional
        A splitter island (round nose at +x, pointed tail) or round at both ends.

    Returns
    -------
    Mesh
        Class ``other_ground``; 0.10-0.15 m high.
    """
    shape = str(rng.choice(["teardrop", "stadium"])) if shape is None else shape
    if shape not in ("teardrop", "stadium"):
        raise ValueError(f"traffic_island shape must be 'teardrop' or 'stadium', got {shape!r}")
    L = float(rng.uniform(3.0, 8.0)) if length is None else float(length)
    W = float(rng.uniform(1.2, 2.5)) if width is None else float(width)
    if not (2.0 <= L <= 20.0 and 1.0 <= W <= 4.0 and W < L):
        raise ValueError(f"traffic_island needs length in [2, 20] and width in [1, 4] m (width < length), got {L}, {W}")
    h = float(rng.uniform(0.10, 0.15))
    top = str(rng.choice(["sidewalk_concrete", "curb_concrete"]))
    outline = _stadium(L, W, 0.15 if shape == "teardrop" else 1.0)
    return centred(_raised(outline, h, top))


def median_strip(rng: np.random.Generator, length: float = 20.0, width: float | None = None) -> Mesh:
    """A raised, paved median along x with tapered noses at both ends.

    Parameters
    ----------
    length : float
        Metres (>= 3).
    width : float, optional
        Metres (0.5-4); drawn (0.8-2.0) when omitted.
    """
    W = float(rng.uniform(0.8, 2.0)) if width is None else float(width)
    if not (length >= 3.0 and 0.5 <= W <= 4.0):
        raise ValueError(f"median_strip needs length >= 3 and width in [0.5, 4] m, got {length}, {W}")
    L = float(length)
    h = float(rng.uniform(0.12, 0.18))
    nose = min(2.0, L / 4)
    # straight sides with pointed, slightly rounded noses
    a = np.linspace(-np.pi / 2, np.pi / 2, 5)
    tip_r = min(0.15, W / 4)
    front = [(L / 2 - tip_r + tip_r * np.cos(t), tip_r * np.sin(t)) for t in a]
    back = [(-L / 2 + tip_r - tip_r * np.cos(t), -tip_r * np.sin(t)) for t in a]
    outline = np.array([(-L / 2 + nose, -W / 2), (L / 2 - nose, -W / 2), *front, (L / 2 - nose, W / 2),
                        (-L / 2 + nose, W / 2), *back])
    top = str(rng.choice(["sidewalk_concrete", "curb_concrete"]))
    return centred(_raised(outline, h, top, kerb_w=min(0.12, W / 5)))


def driveway_apron(rng: np.random.Generator, width: float | None = None, depth: float | None = None) -> Mesh:
    """A driveway crossing: a flared slab that ramps from a 2 cm lip at its road edge (+x) up to
    kerb height at its back edge (-x), where it meets the sidewalk.

    Parameters
    ----------
    width : float, optional
        Along y at the back edge, metres (2.5-8); drawn (3-5) when omitted. The road edge is
        wider by the two flares.
    depth : float, optional
        Along x, metres (0.5-3); drawn (0.8-1.5) when omitted.
    """
    W = float(rng.uniform(3.0, 5.0)) if width is None else float(width)
    D = float(rng.uniform(0.8, 1.5)) if depth is None else float(depth)
    if not (2.5 <= W <= 8.0 and 0.5 <= D <= 3.0):
        raise ValueError(f"driveway_apron needs width in [2.5, 8] and depth in [0.5, 3] m, got {W}, {D}")
    flare = float(rng.uniform(0.4, 0.8))
    lip, h = 0.02, float(rng.uniform(0.12, 0.15))
    mat = str(rng.choice(["sidewalk_concrete", "parking_asphalt"]))
    # corners: road edge (+x) wide, back edge (-x) narrow; tops slope from lip to h
    x0, x1 = -D / 2, D / 2
    top = np.array([[x1, -W / 2 - flare, lip], [x1, W / 2 + flare, lip], [x0, W / 2, h], [x0, -W / 2, h]])
    bottom = top.copy()
    bottom[:, 2] = 0.0
    v = np.concatenate([bottom, top])
    faces = [[4, 5, 6], [4, 6, 7]]                        # top (up and toward +x)
    for i in range(4):                                   # sides, outward
        j = (i + 1) % 4
        faces += [[i, j, 4 + j], [i, 4 + j, 4 + i]]
    c, mside = resolve_ids(CLS, "curb_concrete")
    _, mtop = resolve_ids(CLS, mat)
    return centred(Mesh(v, np.array(faces), c, [mtop, mtop] + [mside] * 8))


def verge_crossing(rng: np.random.Generator, width: float | None = None, depth: float | None = None) -> Mesh:
    """A paved crossing of a grass verge: the hard-standing a house's driveway or path lays across
    the verge between the kerb and the sidewalk, a slab 2.5 cm thick (the layout sinks it 5 mm into
    the grass, so it stands 2 cm proud). Width along x, depth (across the verge) along y.

    Parameters
    ----------
    width : float, optional
        Along x, metres (2-8); drawn (3-4.5) when omitted.
    depth : float, optional
        Along y, metres (0.5-6); drawn (2-3) when omitted.

    Returns
    -------
    Mesh
        Class ``other_ground``; the top paving (``block_paving``, ``sidewalk_concrete`` or
        ``parking_asphalt``, drawn), the sides ``curb_concrete``.
    """
    W = float(rng.uniform(3.0, 4.5)) if width is None else float(width)
    D = float(rng.uniform(2.0, 3.0)) if depth is None else float(depth)
    if not (2.0 <= W <= 8.0 and 0.5 <= D <= 6.0):
        raise ValueError(f"verge_crossing needs width in [2, 8] and depth in [0.5, 6] m, got {W}, {D}")
    top = str(rng.choice(["block_paving", "sidewalk_concrete", "parking_asphalt"]))
    outline = np.array([(-W / 2, -D / 2), (W / 2, -D / 2), (W / 2, D / 2), (-W / 2, D / 2)])
    slab = prism(outline, 0.0, 0.025, CLS, "curb_concrete")
    up = face_normals(slab)[:, 2] > 0.5
    _, m = resolve_ids(CLS, top)
    slab.face_material[up] = m
    keep = face_normals(slab)[:, 2] > -0.5             # no bottom: it lies on the grass
    return centred(slab.select(keep))


def gravel_patch(rng: np.random.Generator, size: float | None = None) -> Mesh:
    """A thin irregular gravel patch (a lobed outline 3-5 cm thick).

    Parameters
    ----------
    size : float, optional
        Mean diameter, metres (1-20); drawn (2-6) when omitted.

    Returns
    -------
    Mesh
        Class ``other_ground``, material ``curb_concrete`` (the grey granular recipe closest to
        gravel among the shipped ones).
    """
    S = float(rng.uniform(2.0, 6.0)) if size is None else float(size)
    if not 1.0 <= S <= 20.0:
        raise ValueError(f"gravel_patch size must be in [1, 20] m, got {S}")
    k = 20
    a = np.linspace(0, 2 * np.pi, k, endpoint=False)
    phases = rng.uniform(0, 2 * np.pi, 3)
    r = 1.0 + 0.12 * np.sin(2 * a + phases[0]) + 0.08 * np.sin(3 * a + phases[1]) + 0.05 * np.sin(5 * a + phases[2])
    outline = np.stack([S / 2 * r * np.cos(a) * 1.2, S / 2 * r * np.sin(a) * 0.85], 1)
    t = float(rng.uniform(0.03, 0.05))
    return centred(prism(outline, 0.0, t, CLS, "curb_concrete"))
