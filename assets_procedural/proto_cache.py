"""Exact cache of asset prototypes: a mesh is built once per (kind, generator state, parameters).

:func:`assets_procedural.catalog.build` goes through :data:`CACHE`. The key is everything a
builder's output depends on -- the kind, the full state of the ``numpy.random.Generator`` it
draws from and its parameters (arrays by dtype, shape and bytes) -- so a hit returns the very
mesh the builder would make, and the generator is left in the state the build would leave it
in. Nothing is quantised: cached or not, the scene has the same bytes. The cache does not look
at what a builder draws.

What it buys: a town built again in the same process (a render worker, ``generate``'s
per-town passes, tests) and the towns of a re-drawn run that share an asset library
(``assets.redraw_every_towns`` > 1 or null) skip the mesh building; a town with a fresh library
builds its meshes once per process. Derived
per-prototype data (collision bands, label hulls) is cached beside the mesh
(:meth:`PrototypeCache.derive`).

Cached meshes are shared between every scene that uses them, so their arrays are made
read-only: code that would change a prototype in place fails loudly instead of changing
other scenes. Least recently used entries are dropped beyond :attr:`PrototypeCache.max_bytes`.
"""

from __future__ import annotations

import hashlib
import logging
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from generator.geometry import Mesh

log = logging.getLogger(__name__)

#: Default bound of the cached arrays (meshes and derived data), bytes.
MAX_BYTES = 512 * 2**20


class Uncacheable(TypeError):
    """A parameter the key cannot describe exactly (the build then bypasses the cache)."""


def _feed(h, value) -> None:
    """Hash ``value`` exactly (type included: 1, 1.0 and True are different keys)."""
    if value is None or isinstance(value, (bool, int, float, str, np.integer, np.floating, np.bool_)):
        h.update(f"{type(value).__name__}:{value!r};".encode())
    elif isinstance(value, np.ndarray):
        a = np.ascontiguousarray(value)
        h.update(f"nd:{a.dtype.str}:{a.shape};".encode())
        h.update(a.tobytes())
    elif isinstance(value, (list, tuple)):
        h.update(f"{type(value).__name__}[{len(value)}];".encode())
        for v in value:
            _feed(h, v)
    elif isinstance(value, dict):
        h.update(f"dict[{len(value)}];".encode())
        for k in sorted(value, key=repr):
            _feed(h, k)
            _feed(h, value[k])
    else:
        raise Uncacheable(type(value).__name__)


def key_of(kind: str, rng: np.random.Generator, params: dict) -> str:
    """The cache key: SHA-256 over the kind, the generator's full bit-generator state and ``params``."""
    h = hashlib.sha256()
    _feed(h, kind)
    _feed(h, rng.bit_generator.state)
    _feed(h, params)
    return h.hexdigest()


def _nbytes(x) -> int:
    if isinstance(x, Mesh):
        return sum(a.nbytes for a in (x.vertices, x.faces, x.face_class, x.face_material)) + \
            sum(a.nbytes for a in x.anchors.values())
    if isinstance(x, np.ndarray):
        return x.nbytes
    return 256


def _freeze(mesh: Mesh) -> Mesh:
    for a in (mesh.vertices, mesh.faces, mesh.face_class, mesh.face_material, *mesh.anchors.values()):
        a.setflags(write=False)
    return mesh


@dataclass
class _Entry:
    mesh: Mesh
    state_after: dict
    nbytes: int
    derived: dict = field(default_factory=dict)


class PrototypeCache:
    """Built meshes by :func:`key_of`, least recently used dropped beyond ``max_bytes``.

    Attributes
    ----------
    hits, misses, bypassed : int
        Builds served from the cache, built and stored, built without a key.
    """

    def __init__(self, max_bytes: int = MAX_BYTES):
        self.max_bytes = int(max_bytes)
        self.enabled = True
        self._entries: OrderedDict[str, _Entry] = OrderedDict()
        self._by_id: dict[int, str] = {}
        self.nbytes = 0
        self.hits = self.misses = self.bypassed = 0

    def __len__(self) -> int:
        return len(self._entries)

    def clear(self) -> None:
        """Forget every entry (the counters too)."""
        self._entries.clear()
        self._by_id.clear()
        self.nbytes = 0
        self.hits = self.misses = self.bypassed = 0

    def build(self, kind: str, rng: np.random.Generator, params: dict, builder: Callable[..., Mesh]) -> Mesh:
        """``builder(rng, **params)``, or the mesh it built before from the same key (``rng`` then
        advanced to where that build left it)."""
        if not self.enabled:
            return builder(rng, **params)
        try:
            key = key_of(kind, rng, params)
        except Uncacheable as e:
            self.bypassed += 1
            log.debug("%s: parameter of type %s not cacheable; built afresh", kind, e)
            return builder(rng, **params)
        entry = self._entries.get(key)
        if entry is not None:
            self._entries.move_to_end(key)
            rng.bit_generator.state = entry.state_after
            self.hits += 1
            return entry.mesh
        mesh = _freeze(builder(rng, **params))
        entry = _Entry(mesh, rng.bit_generator.state, _nbytes(mesh))
        self._entries[key] = entry
        self._by_id[id(mesh)] = key
        self.nbytes += entry.nbytes
        self.misses += 1
        self._evict()
        return mesh

    def derive(self, mesh: Mesh, name: str, fn: Callable[[Mesh], object]):
        """``fn(mesh)``, computed once per cached ``mesh`` and ``name`` (always computed for a mesh
        the cache does not hold). Arrays it returns are made read-only when cached."""
        key = self._by_id.get(id(mesh))
        entry = self._entries.get(key) if key is not None else None
        if entry is None or entry.mesh is not mesh:
            return fn(mesh)
        if name not in entry.derived:
            value = fn(mesh)
            if isinstance(value, Mesh):
                _freeze(value)
            elif isinstance(value, np.ndarray):
                value.setflags(write=False)
            entry.derived[name] = value
            n = _nbytes(value) if value is not None else 0
            entry.nbytes += n
            self.nbytes += n
            self._evict()
        return entry.derived[name]

    def _evict(self) -> None:
        while self.nbytes > self.max_bytes and len(self._entries) > 1:
            key, entry = self._entries.popitem(last=False)
            self._by_id.pop(id(entry.mesh), None)
            self.nbytes -= entry.nbytes


#: The process-wide cache :func:`assets_procedural.catalog.build` uses.
CACHE = PrototypeCache()
