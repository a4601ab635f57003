"""Things that stand proud of a facade: balconies, shop fascia boards and awnings.

Each function draws into a facade of :mod:`assets_procedural.building` through its
``box(u0, u1, v0, v1, w0, w1, material)`` and ``add(corners, material, facing)`` methods
(facade coordinates: ``u`` metres along the edge, ``v`` metres up, ``w`` metres outward
from the wall plane). Every face is class ``building``.
"""

from __future__ import annotations

import numpy as np

from assets_procedural.facade_layout import Hole, Style

SLAB_T = 0.16          #: balcony slab thickness, metres
RAIL_H = 1.0           #: railing height above the slab, metres
FASCIA_H = 0.45        #: shop sign band height, metres (its top stays 4 cm under a first-floor balcony slab)
BLADE_M = (0.65, 0.6)  #: blade sign reach from the wall and height, metres
BLADE_P = 0.35         #: share of shops with a blade sign


def balcony(fc, h: Hole, st: Style, facade_mat: str) -> None:
    """A slab under the balcony door ``h`` and a railing round its three open sides.

    ``solid`` railings are parapet panels in the wall material; ``rails`` are metal posts
    with a handrail and two middle rails (beams pass between them, as through real ones).
    """
    d = st.balcony_depth
    u0, u1 = max(h.u0 - 0.4, 0.1), min(h.u1 + 0.4, fc.length - 0.1)     # never past the facade's ends
    top = h.v0 - 0.05                       # slab top, just under the door sill
    fc.box(u0, u1, top - SLAB_T, top, 0.0, d, "facade_concrete")
    if st.railing == "solid":
        t = 0.06
        fc.box(u0, u1, top, top + RAIL_H, d - t, d, facade_mat)
        fc.box(u0, u0 + t, top, top + RAIL_H, 0.0, d - t, facade_mat)
        fc.box(u1 - t, u1, top, top + RAIL_H, 0.0, d - t, facade_mat)
        return
    r = 0.025
    for v in (top + RAIL_H - 0.05, top + 0.55, top + 0.15):
        fc.box(u0, u1, v, v + (0.05 if v > top + 0.6 else 0.03), d - 2 * r, d, "balcony_metal")
        for u in (u0, u1 - 2 * r):
            fc.box(u, u + 2 * r, v, v + 0.03, 0.0, d - 2 * r, "balcony_metal")
    n_posts = max(2, int(round((u1 - u0) / 0.9)) + 1)
    for u in np.linspace(u0, u1 - 2 * r, n_posts):
        fc.box(u, u + 2 * r, top, top + RAIL_H - 0.05, d - 2 * r, d, "balcony_metal")
    fc.box(u0, u0 + 2 * r, top, top + RAIL_H - 0.05, 0.0, 2 * r, "balcony_metal")
    fc.box(u1 - 2 * r, u1, top, top + RAIL_H - 0.05, 0.0, 2 * r, "balcony_metal")


def shop_front(fc, shops: list[Hole], st: Style, length: float, rng: np.random.Generator,
               signs: np.random.Generator | None = None) -> None:
    """Sign boards over the ground floor, blade signs (drawn from ``signs``, when given) and, for an
    awning style, one awning per shop window.

    Parameters
    ----------
    shops : list of Hole
        The shop-window openings of the front facade (ground floor).
    length : float
        Facade length, metres.
    """
    if not shops:
        return
    top = max(s.v1 for s in shops)
    # one board per shop (split half-way between shop windows, 6 cm apart): each its own colour
    shops = sorted(shops, key=lambda s: s.u0)
    cuts = [0.15] + [(p.u1 + q.u0) / 2 for p, q in zip(shops[:-1], shops[1:], strict=True)] + [length - 0.15]
    for k, (c0, c1) in enumerate(zip(cuts[:-1], cuts[1:], strict=True)):
        fc.box(c0 + (0.03 if k else 0.0), c1 - (0.03 if k < len(cuts) - 2 else 0.0), top + 0.1,
               top + 0.1 + FASCIA_H, 0.0, 0.1, "shop_sign")
    if signs is not None:    # blade signs square to the wall at some shops, over the awnings
        for s in shops:
            u = s.u0 - 0.15
            if signs.random() < BLADE_P and u > 0.4:
                fc.box(u - 0.03, u + 0.03, top + 0.75, top + 0.75 + BLADE_M[1], 0.0, BLADE_M[0], "shop_sign")
    if not st.awning:
        return
    depth = float(rng.uniform(0.8, 1.1))
    drop, valance = 0.4, 0.15
    for s in shops:
        a, b = s.u0 - 0.05, s.u1 + 0.05
        hi, lo = top + 0.06, top + 0.06 - drop
        up = np.array([0.0, 0.0, 1.0]) * depth + fc.n * drop       # the sloping cloth faces up and out
        fc.add([(a, hi, 0.02), (a, lo, depth), (b, lo, depth), (b, hi, 0.02)], "awning", up)
        fc.add([(a, lo, depth), (a, lo - valance, depth), (b, lo - valance, depth), (b, lo, depth)], "awning", fc.n)
        for u, side in ((a, -fc.d), (b, fc.d)):                   # the two cheeks
            fc.add([(u, hi, 0.02), (u, lo, depth), (u, lo - valance, depth), (u, hi - valance, 0.02)], "awning", side)
