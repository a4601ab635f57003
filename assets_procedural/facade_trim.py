"""Facade trim for :mod:`assets_procedural.building` (issue 29 item 5): window surrounds proud of the
wall, rainwater pipes at the corners, and the per-building draws of both.

Drawn from the building's own sub-stream ``substream(rng, "facade_trim")`` (:func:`generator.rng.substream`),
so the draws of the window rhythm, shop fronts and roofs keep their values. Facade coordinates as in
:mod:`assets_procedural.facade_details` (``u`` along the edge, ``v`` up, ``w`` outward, metres). Every
face is class ``building`` (a rainwater pipe on a house is building in Cityscapes and SemanticKITTI).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from assets_procedural.facade_layout import Hole
from generator.geometry import Mesh, cylinder

CLS = "building"
TRIM_W = (0.10, 0.16)    #: width range of a window surround's bars, metres
TRIM_T = 0.04            #: how far a surround stands proud of the wall, metres
PIPE_R = 0.045           #: rainwater pipe radius (a 90 mm downpipe), metres
PIPE_OFF = 0.03          #: gap between the pipe and the wall, metres
PIPE_U = 0.08            #: pipe axis from the wall's end, metres (2.5 cm clear of the sign boards at 0.15)
PIPE_SIDES = 8
#: chance of window surrounds per wall material (render and brick facades often have them)
SURROUND_P = {"plaster": 0.65, "brick": 0.45, "concrete": 0.15, "glass": 0.0}


@dataclass(frozen=True)
class Trim:
    """Per-building trim drawn once: surround bar width (0: none), which corners get a pipe."""

    surround: float
    pipes_front: tuple[bool, bool]    #: at u = 0 and at u = length of the front wall
    pipe_back: tuple[bool, bool]


def draw_trim(g: np.random.Generator, facade: str) -> Trim:
    """The trim of one building (``g``: its ``facade_trim`` sub-stream)."""
    surround = float(g.uniform(*TRIM_W)) if g.random() < SURROUND_P[facade] else 0.0
    front = g.random(2) < (0.55, 0.55)
    back = g.random(2) < (0.35, 0.35)
    if facade == "glass":          # curtain walls drain inside
        front[:], back[:] = False, False
    return Trim(surround, (bool(front[0]), bool(front[1])), (bool(back[0]), bool(back[1])))


def surround(fc, h: Hole, width: float, material: str) -> None:
    """Three bars (top over both sides, the sides down to the sill) ``TRIM_T`` proud of the wall round
    window ``h``, with their outer edges; the opening's reveals are drawn from ``w = TRIM_T`` by the
    caller so no slit opens between bar and reveal. 8 quads."""
    a, b, lo, hi, t = h.u0 - width, h.u1 + width, h.v0, h.v1 + width, TRIM_T
    out, along, back, up = 0, 2, 3, 4      # the facade's facing indices (_Facade._normals)
    q = [((a, h.v1, t), (b, h.v1, t), (b, hi, t), (a, hi, t), out),          # top bar front
         ((a, lo, t), (h.u0, lo, t), (h.u0, h.v1, t), (a, h.v1, t), out),    # left bar front
         ((h.u1, lo, t), (b, lo, t), (b, h.v1, t), (h.u1, h.v1, t), out),    # right bar front
         ((a, hi, 0), (b, hi, 0), (b, hi, t), (a, hi, t), up),               # top of the top bar
         ((a, lo, 0), (a, hi, 0), (a, hi, t), (a, lo, t), back),             # left end, facing -u
         ((b, lo, 0), (b, hi, 0), (b, hi, t), (b, lo, t), along)]             # right end, facing +u
    for *corners, facing in q:
        fc.quads.append(tuple(x for p in corners for x in p))
        fc.materials.append(material)
        fc.facing.append(facing)


def pipes(fc, trim: tuple[bool, bool], top: float) -> list[Mesh]:
    """Rainwater pipes from the ground to ``top`` at the chosen ends of the wall ``fc``, each where no
    balcony or other box stands within 0.3 m of it. (k,) Mesh, ``2 * PIPE_SIDES`` triangles each."""
    out = []
    w = PIPE_OFF + PIPE_R
    for at_end, u in zip(trim, (PIPE_U, fc.length - PIPE_U), strict=True):
        if not at_end or fc.length < 2.0:
            continue
        if any(b[0] < u + 0.3 and b[1] > u - 0.3 and b[5] > 0.12 for b in fc.boxes):
            continue
        m = cylinder(PIPE_R, top, CLS, "drainpipe", sections=PIPE_SIDES, caps=False)
        out.append(Mesh(m.vertices + np.array(fc.point(u, 0.0, w)), m.faces, m.face_class, m.face_material))
    return out
