"""The layout-to-world map of a town whose streets do not cross at right angles.

The layout (:mod:`generator.layout.network.grid` and everything placed on it, and the traffic
simulated on its lanes) is drawn on an axis-aligned grid. A town with
``streets.intersection_angle_deg`` below 90 is then carried into the world by one linear map
``A`` (2x2, on x and y; z unchanged) that sends the grid's x axis to world +x and its y axis to
a unit direction at the drawn angle to it, both scaled by ``1 / sin(angle)``::

    A = [[1, lean * cos(angle)], [0, sin(angle)]] / sin(angle)

Scaled so, a strip of width ``w`` along either grid axis is a strip of perpendicular width ``w``
in the world: lanes, parking strips, sidewalks and kerbs keep the widths the spec asks for,
while lengths along the streets grow by ``1 / sin(angle)`` (blocks become parallelograms, and
every intersection has the angles ``angle`` and ``180 - angle``).

Two kinds of object cross the map differently:

* *shaped* geometry (the ground pieces and the prototypes made for one object from the layout:
  buildings, hedges, fences, walls, rails) is mapped point by point (:meth:`TownMap.affine`),
  so it still fills its lot or follows its street;
* everything else (vehicles, people, poles, trees, signs...) is *rigid*
  (:meth:`TownMap.rigid`): its reference point is mapped and it turns, keeping its shape and size,
  by the angle its street turns: a thing beside an east-west street keeps its heading (those
  streets do not turn), one beside a north-south street turns with it, so a car parked along a
  kerb stays along it and a lamp arm or a driveway apron across a street stays square to the
  kerb. Inside an intersection (no one street to follow) a heading turns to the mapped
  direction (:meth:`TownMap.yaw`), as moving actors' headings always do: they face where they go.

Frames: grid (layout) frame and world frame, metres, z up; yaw in radians counter-clockwise
from +x.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from generator.geometry import pose
from generator.spec.towns import intersection_angle


@dataclass(frozen=True)
class TownMap:
    """The grid -> world map of one town.

    Attributes
    ----------
    angle_deg : float
        Angle between the x-streets and the y-streets in the world, degrees, in (0, 90).
    lean : int
        +1: the y-streets lean towards +x going north (the intersections' acute angles face
        north-east and south-west); -1: towards -x.
    xs, ys, corridor_half, lane_half
        The grid's street lines, corridor and lane half widths (:class:`generator.layout.network.grid.Grid`):
        which street a rigid thing stands by, where the parking strips start. Without them every
        heading turns as :meth:`yaw`.
    """

    angle_deg: float
    lean: int
    xs: tuple = ()               #: grid x of the north-south street centre lines, metres
    ys: tuple = ()               #: grid y of the east-west street centre lines, metres
    corridor_half: float = 0.0   #: half width of a street corridor (kerb to lot line both sides), metres
    lane_half: float = 0.0       #: half width of the lanes (centre line to the parking strips), metres

    @functools.cached_property
    def A(self) -> np.ndarray:
        """(2, 2) float64 linear map, grid xy -> world xy."""
        a = math.radians(self.angle_deg)
        return np.array([[1.0, self.lean * math.cos(a)], [0.0, math.sin(a)]]) / math.sin(a)

    @functools.cached_property
    def A_inv(self) -> np.ndarray:
        """(2, 2) float64 inverse map, world xy -> grid xy."""
        return np.linalg.inv(self.A)

    @functools.cached_property
    def matrix(self) -> np.ndarray:
        """(4, 4) float64 homogeneous form of the map (z unchanged)."""
        m = np.eye(4)
        m[:2, :2] = self.A
        return m

    @property
    def stretch(self) -> float:
        """How much longer a length along either street direction is in the world: 1 / sin(angle)."""
        return 1.0 / math.sin(math.radians(self.angle_deg))

    @property
    def shrink(self) -> float:
        """Smallest singular value of ``A``: the most a grid distance can shrink in the world."""
        return float(np.linalg.svd(self.A, compute_uv=False).min())

    # -- points and directions ------------------------------------------------------------
    def xy(self, points: np.ndarray) -> np.ndarray:
        """(n, 2) or (n, 3) float64 grid points -> world points (z, if given, unchanged)."""
        p = np.array(points, np.float64)
        p[..., :2] = p[..., :2] @ self.A.T
        return p

    def grid_xy(self, points: np.ndarray) -> np.ndarray:
        """(n, 2) or (n, 3) float64 world points -> grid points (the inverse of :meth:`xy`)."""
        p = np.array(points, np.float64)
        p[..., :2] = p[..., :2] @ self.A_inv.T
        return p

    def yaw(self, yaw) -> np.ndarray:
        """World heading of grid heading(s) ``yaw`` (radians), on the same branch: the result
        differs from ``yaw`` by less than 90 degrees, so unwrapped tracks stay unwrapped."""
        yaw = np.asarray(yaw, np.float64)
        d = np.stack([np.cos(yaw), np.sin(yaw)], -1) @ self.A.T
        return yaw + np.angle(np.exp(1j * (np.arctan2(d[..., 1], d[..., 0]) - yaw)))

    def turn(self, x: float, y: float, yaw: float) -> float:
        """Angle (radians) a rigid thing at grid ``(x, y)`` with grid heading ``yaw`` turns by:
        0 beside an east-west street, the north-south streets' turn beside one of those, the turn
        of its own heading (:meth:`yaw`) inside an intersection or without street lines."""
        if not self.xs or not self.ys:
            return float(self.yaw(yaw)) - yaw
        dx = float(np.min(np.abs(np.asarray(self.xs) - x)))
        dy = float(np.min(np.abs(np.asarray(self.ys) - y)))
        if dx <= self.corridor_half and dy <= self.corridor_half:
            return float(self.yaw(yaw)) - yaw
        if dy <= dx:
            return 0.0
        return float(self.yaw(math.pi / 2)) - math.pi / 2

    # -- transforms -----------------------------------------------------------------------
    def rigid(self, transform: np.ndarray) -> np.ndarray:
        """(4, 4) world transform of a rigid object at grid ``transform``: its origin mapped, its
        local frame turned about world z by :meth:`turn` (tilts kept), no shear or scale."""
        psi = math.atan2(transform[1, 0], transform[0, 0])
        d = self.turn(float(transform[0, 3]), float(transform[1, 3]), psi)
        out = np.eye(4)
        out[:3, :3] = pose(yaw=d)[:3, :3] @ transform[:3, :3]
        out[:3, 3] = transform[:3, 3]
        out[:2, 3] = self.A @ transform[:2, 3]
        return out

    def affine(self, transform: np.ndarray) -> np.ndarray:
        """(4, 4) world-from-local of shaped geometry at grid ``transform`` (the map after it)."""
        return self.matrix @ transform

    def square_shear(self, transform: np.ndarray) -> float:
        """``k`` such that the grid direction ``v + k u`` of a street frame (``transform``'s local x =
        u along the street, y = v across) maps square to the street in the world."""
        eu, ev = self.A @ transform[:2, 0], self.A @ transform[:2, 1]
        return float(-(eu @ ev) / (eu @ eu))

    def preimage_boxes(self, boxes: np.ndarray, grid_yaw: float) -> np.ndarray:
        """Grid boxes that contain the preimages of world boxes.

        Parameters
        ----------
        boxes : (k, 7) float64
            World boxes ``(cx, cy, hx, hy, yaw, z0, z1)`` (:func:`generator.layout.placement.placer.world_boxes`).
        grid_yaw : float
            Yaw of the returned boxes in the grid, radians (the object's grid heading).

        Returns
        -------
        (k, 7) float64
            Grid boxes, same layout, each the smallest box at ``grid_yaw`` round the parallelogram
            the map sends onto the world box: boxes apart in the grid are apart in the world.
        """
        b = np.asarray(boxes, np.float64).reshape(-1, 7)
        c, s = np.cos(b[:, 4]), np.sin(b[:, 4])
        half = np.stack([np.stack([b[:, 2] * c, b[:, 2] * s], -1), np.stack([-b[:, 3] * s, b[:, 3] * c], -1)], 1)
        half = half @ self.A_inv.T                       # (k, 2, 2): the two half-edge vectors in the grid
        axes = np.array([[math.cos(grid_yaw), math.sin(grid_yaw)], [-math.sin(grid_yaw), math.cos(grid_yaw)]])
        ext = np.abs(half @ axes.T).sum(1)               # (k, 2) half extents along the grid box's axes
        out = b.copy()
        out[:, :2] = b[:, :2] @ self.A_inv.T
        out[:, 2:4] = ext
        out[:, 4] = grid_yaw
        return out


def draw_town_map(spec, grid=None) -> TownMap | None:
    """The map of ``spec``'s town on ``grid`` (its street lines; without it every rigid heading
    turns as :meth:`TownMap.yaw`): None for right-angle streets, else the angle and lean of
    :func:`generator.spec.towns.intersection_angle`."""
    drawn = intersection_angle(spec)
    if drawn is None:
        return None
    angle, lean = drawn
    if grid is None:
        return TownMap(angle, lean)
    return TownMap(angle, lean, tuple(float(v) for v in grid.xs), tuple(float(v) for v in grid.ys),
                   float(grid.corridor_half), float(grid.lane_half))
