"""Bus shelters: class ``shelter`` (SemanticKITTI other-structure 52 lists "bus stops with a
roof"; Cityscapes building 11 lists "bus stop building"), so neither street_object nor building.

Local frame as for street objects: z up, origin on the ground at the footprint centre, running
along y and open toward +x (the road).
"""

from __future__ import annotations

import numpy as np

from assets_procedural.parts import centred
from generator.geometry import Mesh, box, merge, polygon, pose


def bus_shelter(rng: np.random.Generator, length: float | None = None) -> Mesh:
    """A bus shelter along y, open toward +x: steel posts, a flat roof, glass back wall and side
    panes, an illuminated advertising panel at one end and a bench inside.

    Parameters
    ----------
    length : float, optional
        Metres (2.5-8); drawn (3.5-5.5) when omitted.

    Returns
    -------
    Mesh
        Class ``shelter`` (SemanticKITTI other-structure, Cityscapes building); 1.4-1.8 m deep,
        2.4-2.7 m high.
    """
    L = float(rng.uniform(3.5, 5.5)) if length is None else float(length)
    if not 2.5 <= L <= 8.0:
        raise ValueError(f"bus_shelter length must be in [2.5, 8] m, got {L}")
    cls = "shelter"
    D, H = float(rng.uniform(1.4, 1.7)), float(rng.uniform(2.4, 2.6))
    frame = str(rng.choice(["pole_metal", "fence_metal"]))
    parts: list[Mesh] = []
    bays = max(2, int(round(L / 1.6)))
    ys = np.linspace(-L / 2 + 0.04, L / 2 - 0.04, bays + 1)
    xb = -D / 2 + 0.04
    for y in ys:
        parts.append(box((0.08, 0.08, H), cls, frame, (xb, y, H / 2), bottom=False))
    for y in (ys[0], ys[-1]):
        parts.append(box((0.06, 0.06, H), cls, frame, (D / 2 - 0.35, y, H / 2), bottom=False))
    # roof: a thin slab overhanging to the front, falling slightly toward the back
    roof = box((D + 0.25, L + 0.2, 0.1), cls, frame)
    parts.append(roof.transformed(pose(0.1, 0.0, H + 0.06, pitch=-0.03)))
    # back wall glass between the posts (leaving a 10 cm gap at the bottom), a top rail
    pane_t = 0.012           # toughened glass: a thin slab, so front and back faces never coincide
    for ya, yb in zip(ys[:-1], ys[1:], strict=False):
        parts.append(
            box((pane_t, yb - ya - 0.1, H - 0.25), cls, "car_glass", (xb, (ya + yb) / 2, 0.1 + (H - 0.25) / 2))
        )
    parts.append(box((0.05, L, 0.06), cls, frame, (xb, 0.0, H - 0.1)))
    # side panes; at the +y end an advertising panel lit from inside
    for k, y in enumerate((ys[0], ys[-1])):
        if k == 1:
            parts.append(box((D / 2 - 0.38 - xb - 0.06, 0.12, H - 0.45), cls, frame,
                             ((xb + 0.06 + D / 2 - 0.38) / 2, y, 0.15 + (H - 0.45) / 2), bottom=False))
            for s in (1.0, -1.0):   # poster glass 2 cm proud of the case (no z-fighting)
                qa = np.array([[xb + 0.12, y + s * 0.08, 0.3], [D / 2 - 0.44, y + s * 0.08, 0.3],
                               [D / 2 - 0.44, y + s * 0.08, H - 0.45], [xb + 0.12, y + s * 0.08, H - 0.45]])
                parts.append(polygon(qa, cls, "lamp_glass", (0, s, 0)))
        else:
            x0, x1 = xb + 0.06, D / 2 - 0.38
            parts.append(box((x1 - x0, pane_t, H - 0.25), cls, "car_glass", ((x0 + x1) / 2, y, 0.1 + (H - 0.25) / 2)))
    # bench along the back wall
    for y in np.linspace(-L / 4, L / 4, 2):
        parts.append(box((0.04, 0.04, 0.42), cls, frame, (xb + 0.25, y, 0.21), bottom=False))
    for k in range(3):
        parts.append(box((0.09, L * 0.6, 0.03), cls, "fence_wood", (xb + 0.12 + k * 0.11, 0.0, 0.45)))
    return centred(merge(parts))
