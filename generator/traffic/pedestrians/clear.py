"""Keeping walkers clear of what stands on the pavement: obstacle boxes, box overlap, lane shifts.

Obstacles are the collision bands of every non-ground object of the static town (the prototype
cut into 0.5 m height bands, :func:`generator.layout.placement.prototypes.collision_boxes`), so a tree
crown or a lamp arm above head height does not block the pavement under it while the trunk and
the pole do. Large bands (fences, buildings) are cut into tiles of at most :data:`TILE_M`, so
every obstacle is small and one k-d tree over tile centres finds the candidates of any query.
Objects wholly beyond the town's bounds (the far city, hundreds of metres of blocks whose bands
would cut into millions of tiles) are left out: every walkway lies inside the bounds.

Boxes are rows ``(cx, cy, hx, hy, yaw, z0, z1)``: world-frame centre, half length along ``yaw``,
half width, heading (radians) and the z interval, metres (the layout's collision-box format).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from generator.geometry.boxes import box_pairs_overlap, world_boxes
from generator.layout.placement.prototypes import WHOLE_BOX_KINDS, collision_boxes

#: Classes of flat ground (roads, pavements, terrain...): nothing a walker can bump into.
GROUND_CLASSES = frozenset({"road", "road_marking", "crosswalk", "curb", "sidewalk", "parking", "terrain",
                            "other_ground", "rail_track"})
TILE_M = 1.0      #: obstacle tiles are at most this long and wide
SHIFT_STEP_M = 0.05   #: lateral resolution of a lane shift (at most one step per row along the lane)


@dataclass(frozen=True)
class Body:
    """The footprint envelope of every walker (local frame: x forward, y left, origin centred).

    Attributes
    ----------
    hx, hy : float
        Half length and half width, metres (the largest walking prototype plus a margin).
    height : float
        Tallest walker, metres.
    """

    hx: float
    hy: float
    height: float

    @property
    def radius(self) -> float:
        """Half diagonal: no part of the footprint is farther from the origin, metres."""
        return float(np.hypot(self.hx, self.hy))

    def boxes(self, xy: np.ndarray, yaw: np.ndarray, z0: np.ndarray, grow: float = 0.0) -> np.ndarray:
        """(n, 7) boxes of walkers at (n, 2) positions ``xy`` heading ``yaw`` (n,), feet at ``z0`` (n,)."""
        n = len(xy)
        z0 = np.broadcast_to(np.asarray(z0, np.float64), (n,))
        return np.column_stack([xy[:, 0], xy[:, 1], np.full(n, self.hx + grow), np.full(n, self.hy + grow),
                                np.broadcast_to(yaw, (n,)), z0, z0 + self.height])


def body_of(protos, margin: float) -> Body:
    """The envelope of ``protos`` (objects with ``lo``, ``hi`` (3,) local bounds) grown by ``margin``."""
    lo = np.min([p.lo for p in protos], 0)
    hi = np.max([p.hi for p in protos], 0)
    return Body(float(max(-lo[0], hi[0]) + margin), float(max(-lo[1], hi[1]) + margin), float(hi[2]))


def _tiles(boxes: np.ndarray) -> np.ndarray:
    """Cut (m, 7) boxes into tiles at most :data:`TILE_M` on a side (same yaw and z interval)."""
    out = []
    for b in boxes:
        nx, ny = max(1, int(np.ceil(2 * b[2] / TILE_M))), max(1, int(np.ceil(2 * b[3] / TILE_M)))
        if nx == ny == 1:
            out.append(b[None])
            continue
        c, s = np.cos(b[4]), np.sin(b[4])
        u = (np.arange(nx) + 0.5) / nx * 2 * b[2] - b[2]
        v = (np.arange(ny) + 0.5) / ny * 2 * b[3] - b[3]
        uu, vv = (g.ravel() for g in np.meshgrid(u, v))
        t = np.empty((len(uu), 7))
        t[:, 0], t[:, 1] = b[0] + uu * c - vv * s, b[1] + uu * s + vv * c
        t[:, 2], t[:, 3], t[:, 4:] = b[2] / nx, b[3] / ny, b[4:]
        out.append(t)
    return np.concatenate(out) if out else np.zeros((0, 7))


class Obstacles:
    """The static obstacles a walker's box may not overlap.

    Parameters
    ----------
    scene : generator.world.scene.SceneModel
        The static town.
    top : float
        Bands starting at or above this height (metres, world z) are ignored (above every head).
    keep : callable, optional
        ``keep(xy) -> (n,) bool`` for (n, 2) tile centres: tiles far from every walkway can be dropped.
    """

    def __init__(self, scene, top: float, keep=None):
        cache: dict[str, np.ndarray] = {}
        rows = []
        (bx0, by0), (bx1, by1) = scene.bounds
        for o in scene.objects:
            if o.cls in GROUND_CLASSES:
                continue
            lo, hi = (c := o.box.corners_xy()).min(0), c.max(0)
            if lo[0] > bx1 or lo[1] > by1 or hi[0] < bx0 or hi[1] < by0:
                continue            # beyond the town's bounds (the far city): no walker meets it
            if o.prototype not in cache:
                cache[o.prototype] = collision_boxes(scene.prototypes[o.prototype], whole=o.kind in WHOLE_BOX_KINDS)
            wb = world_boxes(cache[o.prototype], o.transform)
            rows.append(wb[wb[:, 5] < top])
        tiles = _tiles(np.concatenate(rows)) if rows else np.zeros((0, 7))
        if keep is not None and len(tiles):
            tiles = tiles[keep(tiles[:, :2])]
        self.boxes = tiles
        self.reach = float(np.hypot(tiles[:, 2], tiles[:, 3]).max()) if len(tiles) else 0.0
        self._tree = cKDTree(tiles[:, :2]) if len(tiles) else None

    def hit(self, boxes: np.ndarray) -> np.ndarray:
        """(n,) bool: which of the (n, 7) query boxes overlap an obstacle."""
        out = np.zeros(len(boxes), bool)
        if self._tree is None or not len(boxes):
            return out
        r = float(np.hypot(boxes[:, 2], boxes[:, 3]).max()) + self.reach
        pairs = cKDTree(boxes[:, :2]).sparse_distance_matrix(self._tree, r, output_type="ndarray")
        if len(pairs):
            qi, oi = pairs["i"].astype(np.int64), pairs["j"].astype(np.int64)
            np.logical_or.at(out, qi, box_pairs_overlap(boxes[qi], self.boxes[oi]))
        return out


def shift_path(cost: np.ndarray, k0: int) -> np.ndarray | None:
    """The cheapest lateral path through a lane-shift grid.

    Parameters
    ----------
    cost : (n, k) float
        Row = a position along the lane, column = a lateral shift (every :data:`SHIFT_STEP_M`);
        cost of passing the cell, ``inf`` where a walker does not fit.
    k0 : int
        Column of no shift; the path starts and ends there.

    Returns
    -------
    (n,) int or None
        Column per row, moving at most one column per row, of least summed cost; None when
        every path is blocked.
    """
    n, k = cost.shape
    acc = np.full(k, np.inf)
    acc[k0] = cost[0, k0]
    back = np.zeros((n, k), np.int8)
    inf = np.array([np.inf])
    for r in range(1, n):
        left, right = np.concatenate([inf, acc[:-1]]), np.concatenate([acc[1:], inf])
        best = np.minimum(np.minimum(left, acc), right)
        back[r] = np.where(best == acc, 0, np.where(best == left, -1, 1))
        acc = best + cost[r]
    if not np.isfinite(acc[k0]):
        return None
    path = np.empty(n, np.int64)
    path[-1] = k0
    for r in range(n - 1, 0, -1):
        path[r - 1] = path[r] + back[r, path[r]]
    return path


def smooth(x: np.ndarray, sigma: float) -> np.ndarray:
    """(n,) ``x`` smoothed by a Gaussian of ``sigma`` samples (ends held)."""
    if sigma <= 0 or len(x) < 3:
        return x.copy()
    r = int(np.ceil(3 * sigma))
    w = np.exp(-0.5 * (np.arange(-r, r + 1) / sigma) ** 2)
    w /= w.sum()
    return np.convolve(np.pad(x, r, mode="edge"), w, mode="valid")
