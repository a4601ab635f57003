"""A roundabout's ring: its geometry and the paths round its island.

A roundabout keeps the node's kerbs (the cross of two streets ``road_half`` wide) and puts a
raised circular island at the node centre. Right-hand traffic circles it anticlockwise: a
vehicle on lane ``k`` (centred ``o = (k + 0.5) lane_w`` right of its street's centre line)
leaves its lane at the connector start (``entry_m`` from the node centre, where every lane edge
ends), turns right on a *fillet* arc of radius ``f`` onto the ring circle of radius ``R_k``
(centred on the node), follows the ring anticlockwise, and turns right on a second fillet onto
the exit lane. Tangency fixes the ring radius once ``f`` is chosen::

    (R_k + f)^2 = entry_m^2 + (o + f)^2

so with ``f = MIN_RADIUS_M`` (the tightest turn the routes ever make) every arc of every path
has radius >= ``MIN_RADIUS_M``, and the ring is as large as that allows (5.28 m for the default
cross-section: 1 lane of 3.5 m, 2.4 m parking, so ``entry_m`` = 7.75 m). The island keeps
``ISLAND_CLEAR_M`` inside the closest approach of a box as long as the standard car and as wide
as the ego (``2 EGO_HALF_WIDTH_M``) on any path -- the ring radius less the half width, or a corner
where a fillet meets the ring -- so the widest vehicle that drives a route keeps ``ISLAND_CLEAR_M``
off its kerb (3.33 m for the default cross-section). Buses and trucks cannot follow a ring that
small: their boxes cut across the island, as on real compact roundabouts, so the island is a
*truck apron* (a mountable ring :data:`generator.layout.network.measures.APRON_H_M` high that only
long vehicles roll over) round a raised centre that the largest design vehicles (:data:`DESIGN_VEHICLES_M`) keep
``ISLAND_CLEAR_M`` off (1.3 m for the default cross-section; none if it would be under
``CORE_MIN_R_M``: a mini-roundabout, all apron).

The geometry depends only on the cross-section (lanes, lane width, kerb-to-kerb half width), so
every roundabout of a town shares one :class:`Ring` (:attr:`generator.layout.network.grid.Grid.ring`).
Which nodes are roundabouts is drawn in :mod:`generator.layout.network.roundabouts`.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from generator.geometry.boxes import corners
from generator.layout.network.design_vehicle import (
    DESIGN_VEHICLES_M,
    EGO_HALF_WIDTH_M,
    MIN_RADIUS_M,
    RIGHT_RADIUS_M,
    STANDARD_CAR_M,
)
from generator.layout.network.measures import ARM_DIRS
from generator.world.scene import Path

STEP_M = 0.25              #: sampling step of the paths
FILLET_M = MIN_RADIUS_M    #: radius of the entry and exit arcs
ISLAND_CLEAR_M = 0.3       #: the ego (half width EGO_HALF_WIDTH_M) on the inner ring keeps this off the island
KERB_CLEAR_M = 0.2         #: the standard car keeps this off the kerb lines on every path
GRASS_MIN_R_M = 1.2        #: raised centres at least this large carry grass (smaller ones: concrete)
CORE_MIN_R_M = 0.5         #: a raised centre smaller than this is left out (the island is all apron)


@dataclass(frozen=True)
class Ring:
    """Geometry shared by every roundabout of a grid (every node has the same cross-section).

    Attributes
    ----------
    ring_r : (lanes,) float64
        Radius of the ring circle of each lane (lane 0 innermost), metres.
    fillet_r : float
        Radius of the entry and exit arcs, metres.
    island_r : float
        Outer radius of the island (its mountable apron), metres: every car keeps off it.
    core_r : float
        Radius of the raised centre inside the apron, metres (0: the whole island is apron, a
        mini-roundabout): long and wide vehicles, whose boxes cut across the apron on the ring,
        keep off it.
    entry_m : float
        Distance from the node centre to where a connector starts and ends (the lane edges' ends).
    lane_w : float
    """

    ring_r: tuple[float, ...]
    fillet_r: float
    island_r: float
    entry_m: float
    lane_w: float
    core_r: float = 0.0

    @property
    def grass(self) -> bool:
        """Whether the raised centre is large enough to carry grass (and bushes)."""
        return self.core_r >= GRASS_MIN_R_M

    def to_dict(self) -> dict:
        """Plain numbers for metadata."""
        return {"ring_radius_m": [round(r, 3) for r in self.ring_r], "fillet_radius_m": round(self.fillet_r, 3),
                "island_radius_m": round(self.island_r, 3), "raised_core_radius_m": round(self.core_r, 3),
                "entry_m": round(self.entry_m, 3)}


def entry_distance(lanes: int, lane_w: float, road_half: float) -> float:
    """Node centre to the connectors' ends, metres: the right-turn radius of the outer lane plus its
    offset (the formula the lane graph and the routes use)."""
    off = (lanes - 0.5) * lane_w
    r_right = max(MIN_RADIUS_M, min(RIGHT_RADIUS_M, (road_half - 0.3 - off) / (1 - np.sqrt(0.5))))
    return float(r_right + off)


@functools.lru_cache(maxsize=32)
def ring_geometry(lanes: int, lane_w: float, road_half: float) -> Ring | None:
    """The :class:`Ring` of a cross-section, or None when no roundabout fits it (see module docstring)."""
    e, f = entry_distance(lanes, lane_w, road_half), FILLET_M
    o = (np.arange(lanes) + 0.5) * lane_w
    ring_r = -f + np.sqrt(f * f + e * e + o * o + 2 * o * f)
    if ring_r[0] < MIN_RADIUS_M:
        return None
    ring = Ring(tuple(float(r) for r in ring_r), f, 0.0, e, lane_w)
    inner = float(ring_r[0] - EGO_HALF_WIDTH_M)
    core = inner
    for k in range(lanes):
        for x in range(4):
            for y in range(4):
                if x == y:
                    continue
                p = ring_path(ring, np.zeros(2), x, y, k)
                if not _inside_kerbs(p, road_half):
                    return None
                # where a fillet meets the ring the box's inner corners come closer than its side
                inner = min(inner, _closest(p, (STANDARD_CAR_M[0], 2 * EGO_HALF_WIDTH_M)))
                if k == 0:
                    core = min([core] + [_closest(p, size) for size in DESIGN_VEHICLES_M])
    island_r = inner - ISLAND_CLEAR_M
    core_r = core - ISLAND_CLEAR_M
    core_r = core_r if core_r >= CORE_MIN_R_M else 0.0
    return Ring(ring.ring_r, f, island_r, e, lane_w, core_r) if island_r > 0.5 else None


def _closest(path: Path, size: tuple[float, float]) -> float:
    """Closest approach to the node centre (the origin) of a box of ``size`` along ``path``, metres
    (its edges sampled every ~0.25 m: a long box's side passes closer than its corners)."""
    c = _corners(path, size)
    n = int(np.ceil(max(size) / 0.25)) + 1
    edges = c[:, :, None] + (np.roll(c, -1, axis=1) - c)[:, :, None] * np.linspace(0.0, 1.0, n)[None, None, :, None]
    return float(np.hypot(edges[..., 0], edges[..., 1]).min())


def _corners(path: Path, size: tuple[float, float]) -> np.ndarray:
    """(n, 4, 2) corners of a box of ``size`` (length, width) metres centred on every sample of ``path``,
    in the order front left, front right, rear left, rear right (so :func:`_closest`, which samples the
    edges between consecutive corners, samples the front, the rear and the two diagonals)."""
    return corners(path.points[:, :2], path.headings, size)[:, [2, 1, 3, 0]]


def _inside_kerbs(path: Path, road_half: float) -> bool:
    """Whether the standard car's corners along ``path`` (node at the origin) stay on the asphalt
    cross ``|x| < road_half or |y| < road_half`` with ``KERB_CLEAR_M`` to spare."""
    p = _corners(path, STANDARD_CAR_M)
    lim = road_half - KERB_CLEAR_M
    return bool(np.all((np.abs(p[..., 0]) < lim) | (np.abs(p[..., 1]) < lim)))


# -- paths ---------------------------------------------------------------------------------------
# -- paths ---------------------------------------------------------------------------------------
def _right(d: np.ndarray) -> np.ndarray:
    return np.array([d[1], -d[0]])


def _angle(v: np.ndarray) -> float:
    return float(np.arctan2(v[1], v[0]))


def _arc_pts(centre: np.ndarray, r: float, th0: float, sweep: float) -> tuple[np.ndarray, np.ndarray]:
    """(n, 2) points and (n,) headings of an arc from radial angle ``th0`` by ``sweep`` radians
    (positive: anticlockwise)."""
    n = max(2, int(np.ceil(abs(sweep) * r / STEP_M)) + 1)
    th = th0 + sweep * np.linspace(0.0, 1.0, n)
    pts = centre + r * np.stack([np.cos(th), np.sin(th)], 1)
    return pts, th + np.sign(sweep) * np.pi / 2


def _path(pieces: list[tuple[np.ndarray, np.ndarray]], name: str) -> Path:
    pts = np.concatenate([p[k > 0:] for k, (p, _) in enumerate(pieces)])
    hd = np.concatenate([h[k > 0:] for k, (_, h) in enumerate(pieces)])
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
    return Path(name, np.c_[pts, np.zeros(len(pts))], np.angle(np.exp(1j * hd)), s)


def ring_path(ring: Ring, c0: np.ndarray, x: int, y: int, k: int, name: str = "") -> Path:
    """The path of lane ``k`` from arm ``x`` to arm ``y`` round the island of a roundabout centred at
    ``c0`` ((2,) world xy): entry fillet (right), ring arc (anticlockwise), exit fillet (right).

    Returns
    -------
    Path
        Open polyline sampled every ``STEP_M`` metres or finer, z = 0; it starts at the end of the
        lane arriving from arm ``x`` and ends at the start of the lane leaving by arm ``y``.
    """
    a, b = -ARM_DIRS[x], ARM_DIRS[y]
    o, e, f, r = (k + 0.5) * ring.lane_w, ring.entry_m, ring.fillet_r, ring.ring_r[k]
    c_in = c0 - e * a + (o + f) * _right(a)
    c_out = c0 + e * b + (o + f) * _right(b)
    phi_in, phi_out = _angle(c_in - c0), _angle(c_out - c0)
    th0 = _angle(-_right(a))                      # entry fillet: from the lane end, clockwise
    sweep_in = -np.mod(th0 - _angle(c0 - c_in), 2 * np.pi)
    sweep_ring = np.mod(phi_out - phi_in, 2 * np.pi)
    th1 = _angle(c0 - c_out)                      # exit fillet: clockwise onto the exit lane
    sweep_out = -np.mod(th1 - _angle(-_right(b)), 2 * np.pi)
    return _path([_arc_pts(c_in, f, th0, sweep_in), _arc_pts(c0, r, phi_in, sweep_ring),
                  _arc_pts(c_out, f, th1, sweep_out)], name)


def plain_path(entry_m: float, lane_w: float, c0: np.ndarray, x: int, y: int, k: int, name: str = "") -> Path:
    """The connector of a plain node, as :func:`generator.traffic.lanes.paths.connector_path` draws it: a
    straight line across, or a quarter circle of radius ``entry_m -+ o`` (right / left turn)."""
    a, b = -ARM_DIRS[x], ARM_DIRS[y]
    o = (k + 0.5) * lane_w
    t_in, t_out = c0 - entry_m * a + o * _right(a), c0 + entry_m * b + o * _right(b)
    sign = float(np.sign(a[0] * b[1] - a[1] * b[0]))
    if sign == 0:
        n = max(2, int(np.ceil(np.linalg.norm(t_out - t_in) / STEP_M)) + 1)
        pts = t_in + (t_out - t_in) * np.linspace(0.0, 1.0, n)[:, None]
        return _path([(pts, np.full(n, _angle(a)))], name)
    r = entry_m - o if sign < 0 else entry_m + o
    centre = t_in + r * sign * np.array([-a[1], a[0]])
    return _path([_arc_pts(centre, r, _angle(t_in - centre), sign * np.pi / 2)], name)
