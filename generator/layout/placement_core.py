"""Placement machinery: asset prototypes, 3D occupancy, the route keep-out, and the placer.

Every thing in the town is a prototype mesh under a yaw-only transform. Before an object
is accepted the :class:`Placer` checks

* the route keep-out: its oriented box (2D) stays ``clearance + EGO_HALF_WIDTH_M`` away from
  every route sample (:class:`Keepout`);
* the occupancy: its collision boxes (the prototype cut into height bands, so a lamp arm
  or a tree crown does not block the pavement under it) overlap no accepted box
  (:class:`Occupancy`, a uniform grid hash with a vectorised separating-axis test).
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass, field

import numpy as np

from generator.geometry import Mesh, pose
from generator.geometry.boxes import OrientedBox, box_of, world_boxes
from generator.geometry.overlap_kernel import any_overlap
from generator.layout.keepout import Keepout
from generator.rng import stream

EGO_HALF_WIDTH_M = 1.2   #: half the width of the ego vehicle that drives the routes
BAND_M = 0.5             #: height of a collision band
WHOLE_BOX_KINDS = frozenset({"building", "hedge", "fence"})


def collision_boxes(mesh: Mesh, whole: bool = False, band: float = BAND_M, tol: float = 0.15,
                    bounds: np.ndarray | None = None) -> np.ndarray:
    """Conservative local AABBs of ``mesh`` cut into height bands.

    Every triangle whose z-range meets a band contributes its full xy extent to that band;
    consecutive bands with nearly equal extents are merged. ``bounds`` ((2, 3), optional) is
    ``mesh.bounds()`` when the caller has it already.

    Returns
    -------
    (b, 6) float64
        ``(x0, y0, z0, x1, y1, z1)`` per box, local frame, metres.
    """
    lo, hi = mesh.bounds() if bounds is None else bounds
    if whole or mesh.n_faces == 0:
        return np.array([[*lo, *hi]])
    tri = mesh.vertices[mesh.faces]
    tmin, tmax = tri.min(1), tri.max(1)
    edges = np.arange(lo[2], hi[2] + band, band)
    out: list[list[float]] = []
    for z0, z1 in zip(edges[:-1], np.minimum(edges[1:], hi[2])):
        m = (tmin[:, 2] <= z1) & (tmax[:, 2] >= z0)
        if not m.any():
            continue
        xy = [*tmin[m, :2].min(0), *tmax[m, :2].max(0)]
        if out and np.all(np.abs(np.subtract(xy, [out[-1][k] for k in (0, 1, 3, 4)])) < tol):
            prev = out[-1]
            out[-1] = [min(prev[0], xy[0]), min(prev[1], xy[1]), prev[2], max(prev[3], xy[2]), max(prev[4], xy[3]), z1]
        else:
            out.append([xy[0], xy[1], z0, xy[2], xy[3], z1])
    return np.array(out, np.float64)


@dataclass
class Proto:
    """A prototype mesh and what placement needs to know about it."""

    key: str
    kind: str
    mesh: Mesh
    lo: np.ndarray           #: (3,) local AABB min
    hi: np.ndarray           #: (3,) local AABB max
    bands: np.ndarray        #: (b, 6) collision boxes (local)
    params: dict = field(default_factory=dict)
    #: made for one object from the layout (:meth:`Library.unique`): a skewed town maps it point by
    #: point, not rigidly (:mod:`generator.layout.town_map`)
    shaped: bool = False


class Library:
    """Builds prototypes through :func:`assets_procedural.catalog.build` and caches them.

    Instanced kinds get a handful of variants (``key = "<kind>_v<i>"``) built from the
    stream ``("assets", kind, i)``; unique kinds (buildings, fences, hedges) get one
    prototype per object from ``("assets", kind, n)``.
    """

    def __init__(self, seed: int):
        from assets_procedural import catalog  # imported lazily: the layout math does not need it

        from assets_procedural.proto_cache import CACHE

        self.seed = seed
        self._catalog = catalog
        self._cache = CACHE
        self.protos: dict[str, Proto] = {}
        self._unique: dict[str, int] = defaultdict(int)

    def main_class(self, kind: str) -> str:
        return self._catalog.MAIN_CLASS[kind]

    def _make(self, key: str, kind: str, g: np.random.Generator, params: dict, shaped: bool = False) -> Proto:
        mesh = self._catalog.build(kind, g, **params)
        lo, hi = bounds = mesh.bounds()
        whole = kind in WHOLE_BOX_KINDS
        bands = self._cache.derive(mesh, f"bands/{whole}", lambda m: collision_boxes(m, whole=whole, bounds=bounds))
        p = Proto(key, kind, mesh, lo, hi, bands, dict(params), shaped)
        self.protos[key] = p
        return p

    def variant(self, kind: str, i: int, params_fn=None, tag: str = "", stream_kind: str | None = None) -> Proto:
        """Variant ``i`` of an instanced kind; ``params_fn(g) -> dict`` draws its parameters first.

        ``tag`` names a separate family of variants of the same kind (e.g. street trees),
        keyed ``"<kind>_<tag>_v<i>"`` and built from the stream ``("assets", kind, tag, i)``.
        ``stream_kind`` draws from another kind's stream instead: a rider and the bicycle it
        rides are built from the same stream, so they fit each other.
        """
        key = f"{kind}_{tag}_v{i}" if tag else f"{kind}_v{i}"
        if key not in self.protos:
            sk = stream_kind or kind
            g = stream(self.seed, "assets", sk, tag, i) if tag else stream(self.seed, "assets", sk, i)
            self._make(key, kind, g, params_fn(g) if params_fn else {})
        return self.protos[key]

    def unique(self, kind: str, **params) -> Proto:
        """A new prototype of ``kind`` used by one object only."""
        n = self._unique[kind]
        self._unique[kind] += 1
        return self._make(f"{kind}_{n:04d}", kind, stream(self.seed, "assets", kind, n), params, shaped=True)

    def label_proxy(self, key: str):
        """The label hull of prototype ``key`` (:func:`generator.geometry.proxy.label_proxy`), computed
        once per cached prototype mesh."""
        from generator.geometry.proxy import label_proxy

        return self._cache.derive(self.protos[key].mesh, "label_proxy", label_proxy)

    def discard(self, proto: Proto) -> None:
        """Forget a unique prototype whose object was rejected."""
        self.protos.pop(proto.key, None)


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
        return {(i, j) for l, h in zip(lo, hi) for i in range(l[0], h[0] + 1) for j in range(l[1], h[1] + 1)}

    @property
    def boxes(self) -> np.ndarray:
        """(n, 7) accepted boxes ``(cx, cy, hx, hy, yaw, z0, z1)``."""
        return self._buf[: self._n]

    def hits(self, boxes: np.ndarray) -> bool:
        """True if any of ``boxes`` (k, 7) overlaps an accepted box."""
        idx = sorted({i for key in self._keys(boxes) for i in self._cells.get(key, ())})
        if not idx:
            return False
        # boxes_overlap(boxes, self.boxes[idx]).any(), compiled (the same float operations)
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
    (:meth:`generator.layout.town_map.TownMap.preimage_boxes`); a shaped prototype's grid boxes
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
