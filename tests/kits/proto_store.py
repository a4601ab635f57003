"""The asset prototypes of one test run, built once and shared by the pytest-xdist workers (files on disk).

A town's build is mostly its prototype meshes and their derived data (label hulls, collision bands):
the kitti-like town of ``tests/traffic/lanes`` takes ~15 s cold and ~2.5 s once
:data:`assets_procedural.proto_cache.CACHE` holds its library. That cache lives in one process, so
under ``pytest -n 2`` each worker built every library it met, most of them twice in a run.

:func:`install` puts a disk layer under that cache in a pytest worker: on a miss of the process's
cache the mesh is read from the run's folder if a worker built it before, else built and written
there. The file is named by the cache's own exact key (:func:`assets_procedural.proto_cache.key_of`:
the kind, the generator's full state, the parameters) and the builder's code, and holds the mesh and
the generator state the build left, so a read mesh is the mesh the build would make, byte for byte,
and the generator ends where the build would leave it. Derived data is kept the same way, by the
digest of the mesh's arrays, the name and the function's code. The folder is this run's (the workers' common
temporary folder), so no file outlives the code that made it. Files appear whole (written beside,
then renamed), so two workers building the same mesh at once only write the same bytes twice.
Builds quicker than :data:`WORTH_S` are not kept (the other worker builds them again, as before).

Tests that need a build from nothing (the cache's own tests, after ``CACHE.clear()``) wrap it in
:func:`bypassed`.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import pickle
import time
from pathlib import Path

import numpy as np

_STATE = {"folder": None, "off": 0}
#: builds quicker than this (seconds) are not written: reading them back would save little (the run
#: wrote ~3 GB in ~45 000 files when every build was kept)
WORTH_S = 0.003


def _feed_code(h, code) -> None:
    """Hash a code object by its byte code and constants, nested code (comprehensions, lambdas) by the same
    rule: never by ``repr``, which holds the nested code's address and differs in every process."""
    h.update(code.co_code)
    for c in code.co_consts:
        if hasattr(c, "co_code"):
            h.update(b"<code>")
            _feed_code(h, c)
        else:
            h.update(f"{type(c).__name__}:{c!r};".encode())


def _code_of(fn) -> str:
    """The identity of a builder: its qualified name, the hash of its byte code and of the values its closure
    holds (a test's stand-in differs; a function whose closure cannot be pickled is this object only)."""
    code = getattr(fn, "__code__", None)
    if code is None:
        return f"{type(fn).__name__}:{os.getpid()}:{id(fn)}"
    h = hashlib.sha256()
    _feed_code(h, code)
    try:
        h.update(pickle.dumps([c.cell_contents for c in fn.__closure__ or ()], protocol=pickle.HIGHEST_PROTOCOL))
    except Exception:  # noqa: BLE001 -- anything pickle refuses: no sharing for this function
        return f"{fn.__qualname__}:{os.getpid()}:{id(fn)}"
    return f"{getattr(fn, '__module__', '?')}.{fn.__qualname__}:{h.hexdigest()}"


def _mesh_digest(mesh) -> str:
    """SHA-256 of every array of ``mesh`` (dtype, shape and bytes): derived data is keyed by what it is made of."""
    h = hashlib.sha256()
    arrays = [mesh.vertices, mesh.faces, mesh.face_class, mesh.face_material]
    for name in sorted(mesh.anchors):
        h.update(name.encode() + b"\0")
        arrays.append(mesh.anchors[name])
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(f"{a.dtype.str}{a.shape};".encode())
        h.update(a.tobytes())
    return h.hexdigest()


def _file(*parts: str) -> Path:
    return _STATE["folder"] / f"{hashlib.sha256(chr(0).join(parts).encode()).hexdigest()}.pickle"


def _read(path: Path):
    try:
        with open(path, "rb") as f:
            return pickle.load(f)
    except FileNotFoundError:
        return None


def _write(path: Path, value) -> None:
    """``value`` pickled into ``path``, appearing whole; a value pickle refuses is not kept (built again)."""
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        with open(tmp, "wb") as f:
            pickle.dump(value, f, protocol=pickle.HIGHEST_PROTOCOL)
    except (pickle.PicklingError, TypeError, AttributeError):
        tmp.unlink(missing_ok=True)
        return
    os.replace(tmp, path)


def install(folder: Path) -> None:
    """Serve :data:`assets_procedural.proto_cache.CACHE`'s misses from ``folder`` (made if missing)."""
    from assets_procedural import proto_cache

    cache = proto_cache.CACHE
    if _STATE["folder"] is not None:
        return
    folder.mkdir(parents=True, exist_ok=True)
    _STATE["folder"] = folder
    build, derive = cache.build, cache.derive

    def stored_build(kind, rng, params, builder):
        if _STATE["off"] or not cache.enabled:
            return build(kind, rng, params, builder)

        def from_disk(g, **kw):                       # called on a miss, with g as the build would get it
            try:
                path = _file("mesh", proto_cache.key_of(kind, g, kw), _code_of(builder))
            except proto_cache.Uncacheable:
                return builder(g, **kw)
            kept = _read(path)
            if kept is not None:
                mesh, g.bit_generator.state = kept
                return mesh
            t = time.perf_counter()
            mesh = builder(g, **kw)
            if time.perf_counter() - t >= WORTH_S:
                _write(path, (mesh, g.bit_generator.state))
            return mesh

        return build(kind, rng, params, from_disk)

    def stored_derive(mesh, name, fn):
        if _STATE["off"]:
            return derive(mesh, name, fn)

        def from_disk(m):                             # called when the process's cache does not hold it
            path = _file("derived", _mesh_digest(m), name, _code_of(fn))
            kept = _read(path)
            if kept is not None:
                return kept[0]
            t = time.perf_counter()
            value = fn(m)
            if time.perf_counter() - t >= WORTH_S:
                _write(path, (value,))
            return value

        return derive(mesh, name, from_disk)

    cache.build, cache.derive = stored_build, stored_derive


@contextlib.contextmanager
def bypassed():
    """Within: every prototype the process's cache misses is built, none read from the run's folder."""
    _STATE["off"] += 1
    try:
        yield
    finally:
        _STATE["off"] -= 1
