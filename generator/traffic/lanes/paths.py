"""Lane pieces and connector curves of the lane graph (world frame, metres, headings in radians).

A connector runs through a node from lane ``k`` of arm ``x`` to a lane of arm ``y`` (arms 0 east,
1 north, 2 west, 3 south; :data:`generator.layout.network.measures.ARM_DIRS`): straight across,
the route's quarter circle (:func:`connector_path`), or a cubic merge into another slot
(:func:`merge_path`). Every piece is an open :class:`~generator.world.scene.Path` sampled about
every ``STEP_M``.
"""

from __future__ import annotations

import numpy as np

from generator.layout.network.measures import ARM_DIRS
from generator.world.scene import Path

STEP_M = 0.25
KAPPA = 0.5523   #: cubic Bezier handle of a quarter circle, as a share of the radius


def line(p0: np.ndarray, p1: np.ndarray, name: str) -> Path:
    """The straight lane piece from ``p0`` to ``p1`` ((2,) world xy), sampled every ``STEP_M`` or finer."""
    n = max(1, int(np.ceil(np.linalg.norm(p1 - p0) / STEP_M)))
    pts = p0 + (p1 - p0) * (np.arange(n + 1)[:, None] / n)
    hd = np.full(n + 1, np.arctan2(*(p1 - p0)[::-1]))
    s = np.linspace(0.0, float(np.linalg.norm(p1 - p0)), n + 1)
    return Path(name, np.c_[pts, np.zeros(n + 1)], hd, s)


def arc(centre: np.ndarray, r: float, h0: float, sign: float, name: str) -> Path:
    """A quarter circle of radius ``r`` round ``centre`` from heading ``h0``, turning left (``sign`` +1)
    or right (-1)."""
    n = max(2, int(np.ceil(r * np.pi / 2 / STEP_M)))
    ang = h0 + sign * np.pi / 2 * np.arange(n + 1) / n
    radial = ang - sign * np.pi / 2
    pts = centre + r * np.stack([np.cos(radial), np.sin(radial)], 1)
    return Path(name, np.c_[pts, np.zeros(n + 1)], ang, np.linspace(0.0, r * np.pi / 2, n + 1))


def connector_path(c0: np.ndarray, entry_m: float, lane_w: float, x: int, y: int, k: int, name: str = "") -> Path:
    """The connector of lane ``k`` from arm ``x`` to arm ``y`` of a node centred at ``c0`` ((2,) world xy):
    a straight line across, or the route's quarter circle (radius ``entry - o`` right, ``entry + o`` left)."""
    a, b = -ARM_DIRS[x], ARM_DIRS[y]
    right_a, right_b = np.array([a[1], -a[0]]), np.array([b[1], -b[0]])
    o = (k + 0.5) * lane_w
    t_in, t_out = c0 - entry_m * a + o * right_a, c0 + entry_m * b + o * right_b
    sign = float(np.sign(a[0] * b[1] - a[1] * b[0]))
    if sign == 0:
        return line(t_in, t_out, name)
    r = entry_m - o if sign < 0 else entry_m + o
    centre = t_in + r * sign * np.array([-a[1], a[0]])
    return arc(centre, r, float(np.arctan2(a[1], a[0])), sign, name)


def merge_path(c0: np.ndarray, entry_m: float, lane_w: float, x: int, y: int, k_in: int, k_out: int,
               name: str = "") -> Path:
    """A connector from slot ``k_in`` of arm ``x`` to slot ``k_out`` of arm ``y`` of a node centred on
    ``c0`` ((2,) world xy, metres): a cubic Bezier tangent to both lanes (a quarter-circle-like turn,
    or an S-bend across lanes when straight on)."""
    a, b = -ARM_DIRS[x], ARM_DIRS[y]
    right_a, right_b = np.array([a[1], -a[0]]), np.array([b[1], -b[0]])
    p0 = c0 - entry_m * a + (k_in + 0.5) * lane_w * right_a
    p3 = c0 + entry_m * b + (k_out + 0.5) * lane_w * right_b
    if abs(a[0] * b[1] - a[1] * b[0]) < 1e-9:        # straight on: handles a third of the way
        h = float(np.dot(p3 - p0, a)) / 3
        p1, p2 = p0 + h * a, p3 - h * b
    else:                                              # turn: handles towards the tangents' crossing
        s, t = np.linalg.solve(np.stack([a, b], 1), p3 - p0)
        p1, p2 = p0 + KAPPA * s * a, p3 - KAPPA * t * b
    n = max(8, int(np.ceil(np.linalg.norm(p3 - p0) * 1.6 / STEP_M)))
    u = np.linspace(0.0, 1.0, n + 1)[:, None]
    pts = (1 - u) ** 3 * p0 + 3 * (1 - u) ** 2 * u * p1 + 3 * (1 - u) * u ** 2 * p2 + u ** 3 * p3
    der = 3 * (1 - u) ** 2 * (p1 - p0) + 6 * (1 - u) * u * (p2 - p1) + 3 * u ** 2 * (p3 - p2)
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
    return Path(name, np.c_[pts, np.zeros(n + 1)], np.arctan2(der[:, 1], der[:, 0]), s)


def reversed_path(p: Path, name: str) -> Path:
    """``p`` driven the other way (same points, reversed; headings turned round)."""
    return Path(name, p.points[::-1].copy(), np.angle(np.exp(1j * (p.headings[::-1] + np.pi))), p.s[-1] - p.s[::-1])
