"""Regulatory sign faces of one-way streets: "one way" and "no entry" (Vienna Convention, as in Europe).

* ``one_way``: an upright blue rectangle (material ``sign_blue``) with a white arrow pointing up,
  straight ahead for the driver who faces it (E,5a-like; the UK and Ireland post it at the entry);
* ``no_entry``: a red disc (``sign_red``) with a white horizontal bar (C,1a).

The white symbol is a 4 mm plate (``sign_symbol``) on the face, so the camera sees the pattern as
geometry with its own material (and the LiDAR its retroreflective paint), with no texture needed.
Outlines are in the plate frame of :func:`assets_procedural.street_furniture.traffic_sign`:
``(y, z)`` metres around the plate centre, counter-clockwise seen from +x (y right, z up).
"""

from __future__ import annotations

import numpy as np

#: shape -> (size range: width of the rectangle / diameter of the disc, metres; face material)
REGULATORY = {"one_way": ((0.5, 0.6), "sign_blue"), "no_entry": ((0.6, 0.75), "sign_red")}
ONE_WAY_ASPECT = 1.4       #: height / width of the "one way" rectangle
SYMBOL_MATERIAL = "sign_symbol"
SYMBOL_DEPTH_M = 0.004     #: the symbol plate stands this far proud of the face


def plate_outline(shape: str, size: float) -> np.ndarray:
    """(k, 2) float64 outline of the plate of ``shape`` (``size`` metres across), (y, z) metres."""
    if shape == "one_way":
        w, h = size / 2, size * ONE_WAY_ASPECT / 2
        return np.array([(-w, -h), (w, -h), (w, h), (-w, h)])
    a = np.arange(24) * 2 * np.pi / 24
    return size / 2 * np.stack([np.cos(a), np.sin(a)], 1)


def symbol_outlines(shape: str, size: float) -> list[np.ndarray]:
    """The white symbol of ``shape`` as simple counter-clockwise polygons ((k, 2) float64, (y, z) metres).

    ``one_way``: an arrow pointing up (+z) over 80 % of the plate height, shaft 0.16 of the width;
    ``no_entry``: a bar 0.76 of the diameter wide and 0.2 of it high (C,1a's proportions).
    """
    if shape == "one_way":
        h = size * ONE_WAY_ASPECT
        top, bottom, neck = 0.4 * h, -0.4 * h, 0.08 * h
        s, head = 0.08 * size, 0.33 * size
        return [np.array([(-s, bottom), (s, bottom), (s, neck), (head, neck), (0.0, top), (-head, neck), (-s, neck)])]
    w, t = 0.38 * size, 0.1 * size
    return [np.array([(-w, -t), (w, -t), (w, t), (-w, t)])]


def face_of(shape: str, rng: np.random.Generator) -> tuple[np.ndarray, str, list[np.ndarray]]:
    """Draw a regulatory face: ``(plate outline, face material, symbol outlines)`` (one draw: its size)."""
    (lo, hi), material = REGULATORY[shape]
    size = float(rng.uniform(lo, hi))
    return plate_outline(shape, size), material, symbol_outlines(shape, size)
