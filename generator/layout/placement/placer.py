"""The placer: what may stand where. Before an object (a prototype of
:mod:`generator.layout.placement.prototypes` under a yaw-only transform) is accepted the :class:`Placer` checks

* the route keep-out: its oriented box (2D) stays ``clearance + EGO_HALF_WIDTH_M`` away from
  every route sample (:class:`~generator.layout.placement.keepout.Keepout`);
* the occupancy: its collision boxes (the prototype cut into height bands, so a lamp arm
  or a tree crown does not block the pavement under it) overlap no accepted box
  (:class:`Occupancy`, a uniform grid hash with the compiled separating-axis test
  :func:`generator.geometry.overlap_kernel.any_overlap`).
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass

import numpy as np

from generator.geometry import pose
from generator.geometry.boxes import OrientedBox, box_of, world_boxes
from generator.layout.placement.keepout import Keepout
from generator.layout.placement.prototypes import Library, Proto


def oriented_box(proto: Proto, transform: np.ndarray) -> OrientedBox:
    """The object's :class:`OrientedBox`: the prototype's local AABB under ``transform``."""
    return box_of(proto.lo, proto.hi, transform)


class Occupancy:
    """Accepted collision boxes in a uniform grid hash (cells of ``cell`` metres)."""

    def __init__(self, cell: float = 8.0):
        self.cell = cell
        self._buf = np.zeros((256, 7))
        self._cos = np.zeros(256)  # numpy's cos and sin of each accepted box's yaw, made once
        self._sin = np.zeros(256)
        self._n = 0
        self._cells: dict[tuple[int, int], list[int]] = defaultdict(list)

    def _keys(self, b: np.ndarray) -> set[tuple[int, int]]:
        r = np.hypot(b[:, 2], b[:, 3])
        lo = np.floor((b[:, :2] - r[:, None]) / self.cell).astype(int)
        hi = np.floor((b[:, :2] + r[:, None]) / self.cell).astype(int)
        return {(i, j) for a, h in zip(lo, hi, strict=True)
                for i in range(a[0], h[0] + 1) for j in range(a[1], h[1] + 1)}

    @property
    def boxes(self) -> np.ndarray:
        """(n, 7) accepted boxes ``(cx, cy, hx, hy, yaw, z0, z1)``."""
        return self._buf[: self._n]

    def hits(self, boxes: np.ndarray) -> bool:
        """True if any of ``boxes`` (k, 7) overlaps an accepted box."""
        idx = sorted({i for key in self._keys(boxes) for i in self._cells.get(key, ())})
        if not idx:
            return False
        # boxes_overlap(boxes, self.boxes[idx]).any(), compiled (the same float operations); numba is
        # imported on the first question, not with the layout (~0.2 s)
        from generator.geometry.overlap_kernel import any_overlap

        yaw = np.ascontiguousarray(boxes, np.float64)[:, 4]
        return bool(any_overlap(np.ascontiguousarray(boxes, np.float64), np.cos(yaw), np.sin(yaw),
                                self._buf[idx], self._cos[idx], self._sin[idx]))

    def add(self, boxes: np.ndarray) -> None:
        start = self._n
        while start + len(boxes) > len(self._buf):
            self._buf = np.concatenate([self._buf, np.zeros_like(self._buf)])
            self._cos = np.concatenate([self._cos, np.zeros_like(self._cos)])
            self._sin = np.concatenate([self._sin, np.zeros_like(self._sin)])
        self._buf[start:start + len(boxes)] = boxes
        yaw = np.ascontiguousarray(boxes, np.float64)[:, 4]
        self._cos[start:start + len(boxes)] = np.cos(yaw)
        self._sin[start:start + len(boxes)] = np.sin(yaw)
        self._n += len(boxes)
        for k in range(len(boxes)):
            for key in self._keys(boxes[k:k + 1]):
                self._cells[key].append(start + k)


@dataclass
class Placed:
    """An accepted object, before instance ids and names are assigned."""

    kind: str
    cls: str
    proto: str
    transform: np.ndarray
    box: OrientedBox
    attrs: dict


class Placer:
    """Accepts objects that clear the route keep-out and the occupancy.

    Placement runs in the grid (layout) frame. In a skewed town (``town_map`` given) the checks
    are made so that they hold in the world: the keep-out is measured in the world
    (``world_keepout``, route samples mapped) against each object's world footprint, and a rigid
    object enters the occupancy with grid boxes round the preimage of its world boxes
    (:meth:`generator.layout.mapping.town_map.TownMap.preimage_boxes`); a shaped prototype's grid boxes
    are exact preimages already.
    """

    def __init__(self, library: Library, keepout: Keepout, occupancy: Occupancy | None = None, town_map=None):
        self.lib = library
        self.keepout = keepout
        self.occ = occupancy or Occupancy()
        self.placed: list[Placed] = []
        self.town_map = town_map
        #: the keep-out in the world: the same route samples, mapped (None without a map)
        self.world_keepout = None if town_map is None else Keepout(town_map.xy(keepout.points), keepout.limit)

    def _boxes(self, proto: Proto, T: np.ndarray, pad: float, route_check: bool):
        """``(box, collision boxes)`` in the grid frame, or None if the keep-out is violated."""
        tm, box = self.town_map, oriented_box(proto, T)
        if tm is None or proto.shaped:      # grid boxes are the exact preimages of the world's
            if route_check and (self.keepout.violated(box) if tm is None else
                                self.world_keepout.polygon_distance(tm.xy(box.corners_xy())) < self.keepout.limit):
                return None
            return box, world_boxes(proto.bands, T, pad)
        Tw = tm.rigid(T)
        world_box = oriented_box(proto, Tw)
        if route_check and self.world_keepout.violated(world_box):
            return None
        psi = float(np.arctan2(T[1, 0], T[0, 0]))
        (cx, cy, hx, hy, *_), = tm.preimage_boxes(world_box.row(), psi)
        grid_box = OrientedBox((float(cx), float(cy), box.center[2]), (2 * float(hx), 2 * float(hy), box.size[2]), psi)
        return grid_box, tm.preimage_boxes(world_boxes(proto.bands, Tw, pad), psi)

    def fits(self, proto: Proto, T: np.ndarray, pad: float = 0.0) -> bool:
        """Whether ``proto`` under grid transform ``T`` would be accepted (nothing is placed)."""
        checked = self._boxes(proto, T, pad, True)
        return checked is not None and not self.occ.hits(checked[1])

    def try_place(self, proto: Proto, x: float, y: float, z: float, yaw: float, attrs: dict | None = None,
                  pad: float = 0.0) -> bool:
        """Place ``proto`` at (x, y, z) turned by ``yaw`` if it fits; return whether it was placed."""
        T = pose(x, y, z, yaw)
        checked = self._boxes(proto, T, pad, True)
        if checked is None or self.occ.hits(checked[1]):
            return False
        self._accept(proto, T, *checked, attrs)
        return True

    def place_on(self, proto: Proto, x: float, y: float, z: float, yaw: float, attrs: dict | None = None) -> None:
        """Place ``proto`` without the keep-out and occupancy tests: for what rests on an object
        placed (and tested) just before, under the same transform (a rider on its bicycle, rails
        under their tram). Its boxes still enter the occupancy."""
        T = pose(x, y, z, yaw)
        self._accept(proto, T, *self._boxes(proto, T, 0.0, False), attrs)

    def _accept(self, proto: Proto, T: np.ndarray, box: OrientedBox, boxes: np.ndarray, attrs: dict | None) -> None:
        self.occ.add(boxes)
        self.placed.append(Placed(proto.kind, self.lib.main_class(proto.kind), proto.key, T, box, dict(attrs or {})))
