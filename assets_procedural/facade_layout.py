"""Facade layouts for :mod:`assets_procedural.building`: per-building window rhythm and openings.

A :class:`Style` is drawn once per building (window size and spacing, glazing pattern,
paired windows, blank bays, shop fronts, balconies); :func:`holes` turns it into the
openings of one facade in facade coordinates (``u`` metres along the edge, ``v`` metres up).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

PATTERNS = ("single", "mullion", "cross", "ribbon")
BALCONIES = ("none", "every", "alternate", "middle")
RAILINGS = ("solid", "rails")
PIER_M = 0.3          #: wall left between the two windows of a pair


@dataclass(frozen=True)
class Style:
    """Per-building facade rhythm drawn once from the rng (metres)."""

    pitch: float        #: distance between window bays
    win_w: float
    win_h: float
    sill: float         #: window bottom above the floor level
    recess: float       #: glass depth behind the wall plane
    pattern: str        #: one of :data:`PATTERNS` ("ribbon": continuous bands, curtain walls)
    shop: bool          #: ground floor of the front with shop fronts
    paired: bool = False        #: two windows per bay
    blank: float = 0.0          #: share of bays left blank on side and back walls
    balconies: str = "none"     #: which bays of the upper floors get a balcony (front and back)
    railing: str = "solid"
    balcony_depth: float = 1.1
    awning: bool = False        #: shop fronts get fabric awnings


def draw_style(rng: np.random.Generator, height: float, floor_height: float, facade: str) -> Style:
    """A building's facade style; the draw order is fixed so a seed always gives the same style.

    Parameters
    ----------
    height, floor_height : float
        Wall height and storey height, metres.
    facade : str
        Wall material key (``"glass"`` gets ribbon windows and no balconies).
    """
    win_w = float(rng.uniform(0.9, 1.5))
    pattern = str(rng.choice(PATTERNS[:3]))
    paired = bool(rng.random() < 0.25)
    pitch = float(win_w + rng.uniform(1.0, 2.0)) + (win_w + PIER_M if paired else 0.0)
    win_h = float(rng.uniform(1.3, 1.7))
    sill = float(rng.uniform(0.8, 0.95))
    recess = float(rng.uniform(0.12, 0.18))
    shop = bool(height >= 2.5 * floor_height and rng.random() < 0.55)
    blank = float(rng.choice([0.0, 0.0, 0.2, 0.4]))
    balconies = str(rng.choice(BALCONIES, p=[0.45, 0.2, 0.2, 0.15])) if height >= 2 * floor_height else "none"
    railing = str(rng.choice(RAILINGS))
    depth = float(rng.uniform(0.9, 1.3))
    awning = bool(rng.random() < 0.6)
    if facade == "glass":      # curtain wall: bands of glass between thin mullions, spandrels in between
        pitch = float(rng.uniform(1.4, 1.9))
        win_w, paired, pattern, balconies, blank = pitch - 0.12, False, "ribbon", "none", 0.0
        sill, win_h = 0.3, floor_height - 0.6
    return Style(pitch, win_w, win_h, sill, recess, pattern, shop, paired, blank, balconies, railing, depth, awning)


@dataclass(frozen=True)
class Hole:
    """A rectangular opening in facade coordinates (u along the edge, v = z)."""

    u0: float
    u1: float
    v0: float
    v1: float
    kind: str  # "window" | "shop" | "door" | "balcony" (a glazed door onto a balcony)


def columns(length: float, st: Style) -> np.ndarray:
    """(nc,) float: window bay centres along an edge of ``length`` metres."""
    bay = 2 * st.win_w + PIER_M if st.paired else st.win_w
    usable = length - 1.2
    if usable < bay:
        return np.zeros(0)
    nc = int((usable - bay) // st.pitch) + 1
    return length / 2 + (np.arange(nc) - (nc - 1) / 2) * st.pitch


def balcony_bays(nc: int, st: Style) -> np.ndarray:
    """(nc,) bool: which bays of a front or back facade carry balconies."""
    k = np.arange(nc)
    if st.balconies == "every":
        return np.ones(nc, bool)
    if st.balconies == "alternate":
        return k % 2 == (nc // 2) % 2          # symmetric about the middle
    if st.balconies == "middle":
        return np.abs(k - (nc - 1) / 2) <= 0.5 + (nc >= 7)
    return np.zeros(nc, bool)


def holes(rng: np.random.Generator, length: float, n_floors: int, fh: float, st: Style, door: dict | None,
          role: str) -> list[Hole]:
    """Window, balcony-door, shop-front and door openings of one facade.

    Parameters
    ----------
    rng : numpy.random.Generator
        Draws which bays stay blank (side and back walls of a ``blank`` style).
    length : float
        Facade length, metres.
    n_floors : int
        Storeys with windows; ``fh`` the storey height, metres.
    door : dict or None
        ``{"width", "height"}`` for the front facade; gets ``"u"`` (door centre) set.
    role : {"front", "back", "side"}
        Balconies go on fronts and backs, shop fronts on the front, blank bays off the front.
    """
    cols = columns(length, st)
    win_h = min(st.win_h, fh - st.sill - 0.35)
    out: list[Hole] = []
    door_col = None
    if door is not None:
        if len(cols):
            door_col = int(np.argmin(np.abs(cols - length / 2)))
            uc = float(cols[door_col])
            room = 2 * st.pitch - st.win_w - 0.5 if len(cols) > 1 else length - 0.6
        else:
            uc, room = length / 2, length - 0.6
        w = min(door["width"], room, length - 0.6)
        out.append(Hole(uc - w / 2, uc + w / 2, 0.0, min(door["height"], fh - 0.3), "door"))
        door["u"] = uc
    blank = np.zeros(len(cols), bool)
    if role != "front" and st.blank > 0 and len(cols) > 2:
        blank = rng.random(len(cols)) < st.blank
        blank[rng.integers(len(cols))] = False            # never a wholly blank wall
    balcony = balcony_bays(len(cols), st) if role in ("front", "back") else np.zeros(len(cols), bool)
    shop = door is not None and st.shop
    for f in range(n_floors):
        for k, uc in enumerate(cols):
            if blank[k] or (f == 0 and k == door_col):
                continue
            if f == 0 and shop:
                half = st.pitch / 2 - 0.3 if k != door_col else 0.0
                out.append(Hole(uc - half, uc + half, 0.45, min(fh - 0.75, 3.0), "shop"))
                continue
            v0 = f * fh + st.sill
            kind = "balcony" if f > 0 and balcony[k] else "window"
            if kind == "balcony":
                v0 = f * fh + 0.05
            offs = (-(st.win_w + PIER_M) / 2, (st.win_w + PIER_M) / 2) if st.paired and kind == "window" else (0.0,)
            w = st.win_w if kind == "window" else min(st.pitch - 0.5, max(st.win_w, 1.0))
            for o in offs:
                out.append(Hole(uc + o - w / 2, uc + o + w / 2, v0, f * fh + st.sill + win_h, kind))
    return [h for h in out if h.u0 > 0.05 and h.u1 < length - 0.05]


def wall_rects(length: float, height: float, hs: list[Hole]) -> list[tuple[float, float, float, float]]:
    """Rectangles (u0, u1, v0, v1) covering [0, length] x [0, height] minus the holes."""
    vs = sorted({0.0, height, *[h.v0 for h in hs], *[h.v1 for h in hs]})
    rects = []
    for va, vb in zip(vs[:-1], vs[1:], strict=False):
        if vb - va < 1e-6:
            continue
        cuts = sorted((h.u0, h.u1) for h in hs if h.v0 <= va + 1e-9 and h.v1 >= vb - 1e-9)
        u = 0.0
        for u0, u1 in cuts + [(length, length)]:
            if u0 - u > 1e-6:
                rects.append((u, u0, va, vb))
            u = max(u, u1)
    return rects
