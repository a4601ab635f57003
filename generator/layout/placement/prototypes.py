"""Asset prototypes for placement: the library that builds them, and their collision boxes.

Every thing in the town is a prototype mesh under a yaw-only transform. :class:`Library` builds the
prototypes through :func:`assets_procedural.catalog.build` (the one place the layout calls the asset
builders) and caches them; each :class:`Proto` carries its local bounds and its collision boxes
(the prototype cut into height bands, :func:`collision_boxes`, so a lamp arm or a tree crown does
not block the pavement under it).
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass, field

import numpy as np

from generator.geometry import Mesh
from generator.rng import stream

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
    for z0, z1 in zip(edges[:-1], np.minimum(edges[1:], hi[2]), strict=True):
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
    #: point, not rigidly (:mod:`generator.layout.mapping.town_map`)
    shaped: bool = False


class Library:
    """Builds prototypes through :func:`assets_procedural.catalog.build` and caches them.

    Instanced kinds get variants (``key = "<kind>_v<i>"``) built from the stream
    ``("assets", kind, i)``; how many a kind gets is ``counts[kind]`` (the spec's
    ``assets.variants``, :func:`generator.layout.placement.variety.variant_counts`), else the
    caller's default. Unique kinds (buildings, fences, hedges) get one prototype per object from
    ``("assets", kind, n)``. ``seed`` is the library's own
    (:func:`generator.spec.towns.library_seed`): re-drawn towns get fresh libraries.
    """

    def __init__(self, seed: int, counts: dict[str, int] | None = None):
        from assets_procedural import catalog  # imported lazily: the layout math does not need it
        from assets_procedural.proto_cache import CACHE

        self.seed = seed
        self.counts = dict(counts or {})
        self._catalog = catalog
        self._cache = CACHE
        self.protos: dict[str, Proto] = {}
        self._unique: dict[str, int] = defaultdict(int)

    def __getstate__(self) -> dict:
        """Pickled without the catalog module and the process's prototype cache (they are this process's)."""
        return {k: v for k, v in self.__dict__.items() if k not in ("_catalog", "_cache")}

    def __setstate__(self, state: dict) -> None:
        from assets_procedural import catalog
        from assets_procedural.proto_cache import CACHE

        self.__dict__.update(state)
        self._catalog, self._cache = catalog, CACHE

    def count(self, kind: str, default: int) -> int:
        """Variants of instanced ``kind`` in this library (``default`` when the spec does not say)."""
        return int(self.counts.get(kind, default))

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
