"""The street grid: block sizes, street centre lines, segments and intersections, and the areas they cover.

The town is a grid of ``blocks_x x blocks_y`` blocks separated (and surrounded) by two-way
streets. Street centre lines run at ``Grid.xs`` (north-south streets) and ``Grid.ys``
(east-west streets); they meet at intersections ("nodes") ``(i, j)`` at ``(xs[i], ys[j])``.

Cross-section of every street, from its centre line outwards (metres)::

    |<- lanes_per_direction * lane_width ->|<- parking ->|<- curb ->|<- sidewalk ->|
    0                                      lane_half     road_half  walk_inner     corridor_half

Road and parking surfaces are at z = 0 (the world's road plane); curbs and sidewalks rise to
``curb_height_m``, as do lot grounds and the terrain. Beyond the outer ring road's outer
sidewalks (:attr:`Grid.corridor_rect`) a band of lots ``Grid.outer_depth`` deep runs round
the town (:mod:`generator.layout.lots.outskirts`); the *built area* (:attr:`Grid.built_rect`) ends
there, the terrain margin surrounds it, and flat terrain continues to the horizon. A *segment* is the stretch of one
street between two adjacent intersections; its local frame has ``u`` along the street (from
the start intersection's edge, metres) and ``v`` to the left, so right-hand traffic driving
towards +u uses the lanes at ``v < 0``. With ``streets.roundabouts`` some four-arm nodes are
roundabouts (:mod:`generator.layout.network.roundabouts`); with ``streets.closed_streets`` some segments
are closed (:attr:`Grid.closed`, not in :attr:`Grid.segments`; :mod:`generator.layout.network.closures`).
The grid is drawn from the spec by :func:`generator.layout.network.draw.make_grid`; its ground meshes
are :mod:`generator.layout.ground`.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from generator.geometry import pose
from generator.layout.network.cross_sections import MEDIAN_W_M, PLAIN, CrossSection
from generator.layout.network.measures import (
    APRON_H_M,
    ARM_STEP,
    BAY_M,
    PARKING_START_U,
)
from generator.layout.network.rings import Ring, ring_geometry


@dataclass(frozen=True)
class Segment:
    """One street between two adjacent intersections.

    Attributes
    ----------
    index : int
        Position in :attr:`Grid.segments`.
    axis : int
        0 for an east-west street (u = +x), 1 for a north-south street (u = +y).
    a, b : tuple of int
        Start and end node ``(i, j)``.
    origin : (2,) float
        World xy of the street centre at the start intersection's edge.
    length : float
        Metres between the two intersection squares (the road surface of the segment).
    """

    index: int
    axis: int
    a: tuple[int, int]
    b: tuple[int, int]
    origin: tuple[float, float]
    length: float

    @property
    def yaw(self) -> float:
        """Direction of +u, radians."""
        return 0.0 if self.axis == 0 else np.pi / 2

    def transform(self, z: float = 0.0) -> np.ndarray:
        """(4, 4) world-from-segment transform (u, v, z) -> world."""
        return pose(self.origin[0], self.origin[1], z, self.yaw)

    def to_world(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        """(n, 2) float64 world xy of segment coordinates ``u``, ``v`` (metres)."""
        u, v = np.broadcast_arrays(np.asarray(u, float), np.asarray(v, float))
        if self.axis == 0:
            return np.stack([self.origin[0] + u, self.origin[1] + v], -1).reshape(-1, 2)
        return np.stack([self.origin[0] - v, self.origin[1] + u], -1).reshape(-1, 2)

    def rect_world(self, u0: float, u1: float, v0: float, v1: float) -> tuple[float, float, float, float]:
        """The segment-frame rectangle ``[u0, u1] x [v0, v1]`` as a world AABB (x0, y0, x1, y1)."""
        p = self.to_world([u0, u1], [v0, v1])
        return (float(p[:, 0].min()), float(p[:, 1].min()), float(p[:, 0].max()), float(p[:, 1].max()))


def segment_frame_points(seg: Segment, xy: np.ndarray) -> np.ndarray:
    """(n, 2) segment-frame ``(u, v)`` of world points ``xy`` ((n, 2) metres)."""
    d = np.asarray(xy, np.float64).reshape(-1, 2) - np.asarray(seg.origin)
    return d if seg.axis == 0 else np.stack([d[:, 1], -d[:, 0]], 1)


@dataclass(frozen=True)
class Grid:
    """The street grid and its cross-section (all lengths in metres, world frame)."""

    xs: np.ndarray                   #: (blocks_x + 1,) float64 x of north-south street centres
    ys: np.ndarray                   #: (blocks_y + 1,) float64 y of east-west street centres
    lanes: int                       #: lanes per direction
    lane_w: float
    parking_w: float
    curb_w: float
    sidewalk_w: float
    curb_h: float
    margin: float
    segments: tuple[Segment, ...]
    outer_depth: float = 0.0         #: depth of the lot band outside the outer ring road
    sections: tuple[CrossSection, ...] = ()   #: per segment; () = every street plain
    roundabouts: frozenset = frozenset()       #: nodes ``(i, j)`` that are roundabouts (:mod:`.roundabouts`)
    closed: tuple = ()                         #: closed segments, not in ``segments`` (:mod:`.closures`)

    def section(self, seg: Segment) -> CrossSection:
        """The cross-section type of ``seg`` (see :mod:`generator.layout.network.cross_sections`)."""
        return self.sections[seg.index] if self.sections else PLAIN

    def is_roundabout(self, node: tuple[int, int]) -> bool:
        """Whether ``node`` is a roundabout (an island at its centre, no signals)."""
        return tuple(node) in self.roundabouts

    @property
    def ring(self) -> Ring | None:
        """The :class:`~generator.layout.network.rings.Ring` every roundabout of this cross-section has,
        or None when none fits it."""
        return ring_geometry(self.lanes, float(self.lane_w), float(self.road_half))

    def islands(self) -> np.ndarray:
        """(k, 4) float64 ``(x, y, apron radius, raised centre radius)`` of the roundabout islands."""
        if not self.roundabouts:
            return np.zeros((0, 4))
        ring = self.ring
        return np.array([(*self.node_xy(n), ring.island_r, ring.core_r) for n in sorted(self.roundabouts)], np.float64)

    def strip_span(self, seg: Segment) -> tuple[float, float] | None:
        """(u0, u1) of the middle stretch where ``seg``'s side strips differ (parking bays, verges,
        shoulders, a median), or None if the segment is too short for one bay or has no strips."""
        u0, u1 = PARKING_START_U, seg.length - PARKING_START_U
        return (u0, u1) if self.parking_w > 0 and u1 - u0 >= BAY_M else None

    @property
    def lane_half(self) -> float:
        """Centre line to the outer edge of the driving lanes."""
        return self.lanes * self.lane_w

    @property
    def road_half(self) -> float:
        """Centre line to the curb face (kerb-to-kerb half width)."""
        return self.lane_half + self.parking_w

    @property
    def walk_inner(self) -> float:
        """Centre line to the inner edge of the sidewalk (behind the curb)."""
        return self.road_half + self.curb_w

    @property
    def corridor_half(self) -> float:
        """Centre line to the outer edge of the sidewalk (where lots begin)."""
        return self.walk_inner + self.sidewalk_w

    @property
    def nodes(self) -> list[tuple[int, int]]:
        """Every intersection ``(i, j)``, row-major in j then i."""
        return [(i, j) for j in range(len(self.ys)) for i in range(len(self.xs))]

    @property
    def corridor_rect(self) -> tuple[float, float, float, float]:
        """(x0, y0, x1, y1): the street grid up to the outer edge of the outer ring's outer sidewalks."""
        c = self.corridor_half
        return (float(self.xs[0] - c), float(self.ys[0] - c), float(self.xs[-1] + c), float(self.ys[-1] + c))

    @property
    def built_rect(self) -> tuple[float, float, float, float]:
        """(x0, y0, x1, y1): the built area, the street grid plus the outer lot band."""
        x0, y0, x1, y1 = self.corridor_rect
        d = self.outer_depth
        return (x0 - d, y0 - d, x1 + d, y1 + d)

    @property
    def bounds(self) -> np.ndarray:
        """(2, 2) float64 [[xmin, ymin], [xmax, ymax]] of the town: the built area and the margin
        (the terrain to the horizon lies outside)."""
        x0, y0, x1, y1 = self.built_rect
        e = self.margin
        return np.array([[x0 - e, y0 - e], [x1 + e, y1 + e]])

    def node_xy(self, node: tuple[int, int]) -> np.ndarray:
        return np.array([self.xs[node[0]], self.ys[node[1]]])

    def block_rect(self, i: int, j: int) -> tuple[float, float, float, float]:
        """Block ``(i, j)`` inside its sidewalks: (x0, y0, x1, y1)."""
        c = self.corridor_half
        return (self.xs[i] + c, self.ys[j] + c, self.xs[i + 1] - c, self.ys[j + 1] - c)

    def segment_between(self, a: tuple[int, int], b: tuple[int, int]) -> tuple[Segment, int]:
        """The segment joining adjacent nodes ``a`` and ``b`` and the direction (+1: a->b is +u)."""
        for s in self.segments:
            if (s.a, s.b) == (a, b):
                return s, 1
            if (s.a, s.b) == (b, a):
                return s, -1
        raise KeyError(f"nodes {a} and {b} are not adjacent")

    def arms(self, node: tuple[int, int]) -> list[int]:
        """Directions (0 = east, 1 = north, 2 = west, 3 = south) in which streets leave ``node``."""
        i, j = node
        out = []
        if i < len(self.xs) - 1:
            out.append(0)
        if j < len(self.ys) - 1:
            out.append(1)
        if i > 0:
            out.append(2)
        if j > 0:
            out.append(3)
        shut = {c.b if c.a == node else c.a for c in self.closed if node in (c.a, c.b)}
        return [d for d in out if (i + int(ARM_STEP[d][0]), j + int(ARM_STEP[d][1])) not in shut]

    # -- areas used by placement and tests ---------------------------------------------------
    def road_rects(self) -> np.ndarray:
        """(k, 4) float64 world AABBs (x0, y0, x1, y1) of kerb-to-kerb road (streets + intersections)."""
        r = self.road_half
        if self.closed:     # every open segment and every node square
            out = [s.rect_world(0.0, s.length, -r, r) for s in self.segments]
            out += [(x - r, y - r, x + r, y + r) for x, y in (self.node_xy(n) for n in self.nodes)]
            return np.array(out, np.float64)
        rows = [(self.xs[0] - r, y - r, self.xs[-1] + r, y + r) for y in self.ys]
        cols = [(x - r, self.ys[0] - r, x + r, self.ys[-1] + r) for x in self.xs]
        return np.array(rows + cols, np.float64)

    def lane_rects(self) -> list[tuple[Segment, int, int, tuple[float, float, float, float]]]:
        """Driving lanes of every segment: ``(segment, direction, lane, (x0, y0, x1, y1))``.

        ``direction`` is +1 for traffic towards +u (lanes at v < 0), -1 otherwise; ``lane`` 0
        is next to the centre line.
        """
        out = []
        for s in self.segments:
            for d in (1, -1):
                for k in range(self.lanes):
                    v0, v1 = sorted((-d * k * self.lane_w, -d * (k + 1) * self.lane_w))
                    out.append((s, d, k, s.rect_world(0.0, s.length, v0, v1)))
        return out

    def drivable_rects(self) -> np.ndarray:
        """(k, 4) world AABBs of driving-lane asphalt: every lane band plus the intersection squares
        and the parking-free segment ends (where turning arcs run)."""
        r, lh = self.road_half, self.lane_half
        out = [s.rect_world(0.0, s.length, -lh, lh) for s in self.segments]
        for s in self.segments:
            out.append(s.rect_world(0.0, min(PARKING_START_U, s.length), -r, r))
            out.append(s.rect_world(max(0.0, s.length - PARKING_START_U), s.length, -r, r))
        for n in self.nodes:
            x, y = self.node_xy(n)
            out.append((x - r, y - r, x + r, y + r))
        return np.array(out, np.float64)

    def parking_rects(self) -> list[tuple[Segment, int, tuple[float, float, float, float]]]:
        """Parking strips: ``(segment, side, (x0, y0, x1, y1))``; side -1 is the v < 0 strip."""
        if self.parking_w <= 0:
            return []
        out = []
        for s in self.segments:
            u0, u1 = PARKING_START_U, s.length - PARKING_START_U
            if u1 - u0 < BAY_M:
                continue
            for side in (-1, 1):
                if self.section(s).strip(side) != "parking":
                    continue
                v0, v1 = sorted((side * self.lane_half, side * self.road_half))
                out.append((s, side, s.rect_world(u0, u1, v0, v1)))
        return out

    def raised_rects(self) -> list[tuple[Segment, str, tuple[float, float, float, float]]]:
        """Islands raised to curb height between the curbs: ``(segment, "verge" | "median", AABB)``."""
        out = []
        for s in self.segments:
            sec, span = self.section(s), self.strip_span(s)
            if span is None:
                continue
            for side in (-1, 1):
                if sec.strip(side) == "verge":
                    v0, v1 = sorted((side * self.lane_half, side * self.road_half))
                    out.append((s, "verge", s.rect_world(span[0], span[1], v0, v1)))
            if sec.median:
                out.append((s, "median", s.rect_world(span[0], span[1], -MEDIAN_W_M / 2, MEDIAN_W_M / 2)))
        return out

    @functools.cached_property
    def _ground_areas(self) -> tuple[list, list, np.ndarray]:
        """What :meth:`ground_height` tests points against: road AABBs, raised AABBs, islands -- made once
        (the grid is frozen; a pedestrian walk network asks ~36k times)."""
        return (list(self.road_rects()), [r for _, _, r in self.raised_rects()], self.islands())

    def ground_height(self, xy: np.ndarray) -> np.ndarray:
        """(n,) float64 height of the ground surface at world points ``xy`` ((n, 2) metres).

        0 on the road (kerb to kerb, intersections included, verges, median and roundabout
        islands excepted), ``APRON_H_M`` on a roundabout's apron, ``curb_h`` elsewhere (curbs,
        sidewalks, verges, islands, lots, terrain).
        """
        xy = np.asarray(xy, np.float64).reshape(-1, 2)
        road, raised, islands = self._ground_areas
        on_road = np.zeros(len(xy), bool)
        for x0, y0, x1, y1 in road:
            on_road |= (xy[:, 0] > x0) & (xy[:, 0] < x1) & (xy[:, 1] > y0) & (xy[:, 1] < y1)
        for x0, y0, x1, y1 in raised:
            on_road &= ~((xy[:, 0] > x0) & (xy[:, 0] < x1) & (xy[:, 1] > y0) & (xy[:, 1] < y1))
        h = np.where(on_road, 0.0, self.curb_h)
        for x, y, r, core in islands:
            d2 = (xy[:, 0] - x) ** 2 + (xy[:, 1] - y) ** 2
            h[d2 < r * r] = APRON_H_M
            h[d2 < core * core] = self.curb_h
        return h
