"""Embree 4 called directly: the library ``embreex`` ships, bound with ``ctypes``, cast from a compiled loop.

Why
---
``embreex`` (4.4) wraps one call, ``EmbreeScene.run``, and pays for it: on the default town
(1.9 M triangles, 120 moving cars) its scene build takes ~8x the time of a plain
``rtcCommitScene`` (4.95 s against 0.63 s) and a sweep with beam divergence up to ~1.2x the
time of the same ``rtcIntersect1`` calls made from a compiled loop (``bench/lidar_traffic.py``
prints both backends side by side). The LiDAR spends most of a sweep in Embree, so this module binds the handful of
Embree functions the caster needs against the very library ``embreex`` installs (no other
download, no compiler): a device, a scene of one shared triangle buffer, ``rtcIntersect1``.

Watertight or fast
------------------
By default the scene is built without ``RTC_SCENE_FLAG_ROBUST``: on the default town a sweep's casts
take 1/1.29 of the time (``bench/lidar_traffic.py`` and ``docs/lidar.md`` give the figures). The
price: Embree's fast triangle test is not watertight, so about one ray in a million meets the
neighbour across a shared edge or slips through it to the surface behind, and about 2.5 % of the
distances differ from the watertight test's in their last bit. ``Scene(..., robust=True)`` builds
the watertight scene ``embreex`` builds, with its default (medium) build quality: then the hit
triangle and the ``tfar`` of every ray are the same bits as ``embreex``'s (a test casts a town
through both).

Threads
-------
:func:`cast` is compiled with the GIL released and each call owns its ray record, so callers
cast from several threads at once (:mod:`generator.lidar.scan` splits the rays). The kernel
calls a ``ctypes`` function, so numba cannot cache it on disk: it is compiled once per process
(~0.3 s with the library's loading), the first time a scene is built.

Where the library is not found (a platform whose ``embreex`` wheel lays its files out
differently), :func:`available` is False and :class:`generator.lidar.caster.EmbreeCaster` uses
``embreex.run`` itself: same hits, slower.
"""

from __future__ import annotations

import ctypes
import glob
import logging
import os
from functools import cache

import numpy as np

log = logging.getLogger(__name__)

_TRIANGLE, _INDEX, _VERTEX = 0, 0, 1  # RTC_GEOMETRY_TYPE_TRIANGLE, RTC_BUFFER_TYPE_INDEX / _VERTEX
_UINT3, _FLOAT3 = 0x5003, 0x9003  # RTC_FORMAT_UINT3, RTC_FORMAT_FLOAT3
_ROBUST = 4  # RTC_SCENE_FLAG_ROBUST
_VERSION = 0  # RTC_DEVICE_PROPERTY_VERSION
#: file names of the Embree 4 library inside an embreex install (Linux, macOS, Windows wheels)
_PATTERNS = ("embreex.libs/libembree4*.so*", "embreex/.dylibs/libembree4*.dylib", "embreex.libs/embree4*.dll",
             "embreex/embree4*.dll")


@cache
def _library() -> ctypes.CDLL | None:
    try:
        import embreex
    except ImportError:
        return None
    root = os.path.dirname(os.path.dirname(embreex.__file__))
    for pattern in _PATTERNS:
        for path in sorted(glob.glob(os.path.join(root, pattern))):
            try:
                lib = ctypes.CDLL(path)
            except OSError as e:
                log.debug("cannot load %s: %s", path, e)
                continue
            _declare(lib)
            return lib
    return None


def _declare(lib: ctypes.CDLL) -> None:
    p, s, u = ctypes.c_void_p, ctypes.c_size_t, ctypes.c_uint
    for name, res, args in (
        ("rtcNewDevice", p, [ctypes.c_char_p]), ("rtcGetDeviceError", u, [p]),
        ("rtcGetDeviceProperty", ctypes.c_ssize_t, [p, u]),
        ("rtcNewScene", p, [p]), ("rtcSetSceneFlags", None, [p, u]), ("rtcCommitScene", None, [p]),
        ("rtcReleaseScene", None, [p]), ("rtcNewGeometry", p, [p, u]),
        ("rtcSetSharedGeometryBuffer", None, [p, u, u, u, p, s, s, s]), ("rtcCommitGeometry", None, [p]),
        ("rtcAttachGeometry", u, [p, p]), ("rtcReleaseGeometry", None, [p]),
    ):
        fn = getattr(lib, name)
        fn.restype, fn.argtypes = res, args


def available() -> bool:
    """True when the Embree library of the ``embreex`` install could be loaded."""
    return _library() is not None


@cache
def _device() -> int:
    lib = _library()
    dev = lib.rtcNewDevice(None)
    if not dev:
        raise RuntimeError("Embree could not create a device")
    return dev


def version() -> str | None:
    """Embree's version (e.g. ``"4.4.0"``), or None when the library is not available."""
    if not available():
        return None
    v = _library().rtcGetDeviceProperty(_device(), _VERSION)
    return f"{v // 10000}.{v // 100 % 100}.{v % 100}"


#: how far outside a scene's bounding box a ray must pass to be taken as a miss without a cast, metres
BOX_MARGIN_M = 1e-2


def _box_test():
    from numba import njit

    @njit(nogil=True, inline="always")
    def misses_box(boxes, s, o, d, k, tfar):  # pragma: no cover - compiled
        """Ray ``k``'s segment ``[0, tfar]`` passes outside box ``s`` (lo xyz, hi xyz, already grown by
        :data:`BOX_MARGIN_M`): no triangle of the scene can be hit, so Embree would report a miss."""
        t0, t1 = 0.0, np.float64(tfar)
        for a in range(3):
            oa, da = np.float64(o[k, a]), np.float64(d[k, a])
            lo, hi = boxes[s, a], boxes[s, 3 + a]
            if da == 0.0:
                if oa < lo or oa > hi:
                    return True
                continue
            ta, tb = (lo - oa) / da, (hi - oa) / da
            if ta > tb:
                ta, tb = tb, ta
            t0, t1 = max(t0, ta), min(t1, tb)
            if t0 > t1:
                return True
        return False

    return misses_box


@cache
def _kernel():
    """The compiled cast loop, bound to this process's ``rtcIntersect1``: ray ``k`` is cast into scene
    ``scenes[which[k]]`` (``which`` of length 1: every ray into ``scenes[which[0]]``)."""
    from numba import njit

    size = ctypes.c_size_t
    _misses_box = _box_test()
    intersect1 = ctypes.CFUNCTYPE(None, size, size, size)(("rtcIntersect1", _library()))

    @njit(nogil=True, boundscheck=False)
    def cast(scenes, which, o, d, tfar, boxes, dist, prim):  # pragma: no cover - compiled
        # one 64-byte aligned RTCRayHit (32 four-byte fields) per call, allocated here: no Python object
        raw = np.zeros(48, np.uint32)
        off = ((64 - raw.ctypes.data % 64) % 64) // 4
        rec_u = raw[off:off + 32]
        rec = rec_u.view(np.float32)
        p = rec_u.ctypes.data
        one = tfar.shape[0] == 1
        same = which.shape[0] == 1
        boxed = boxes.shape[0] > 0
        for k in range(o.shape[0]):
            s = which[0] if same else which[k]
            if boxed and _misses_box(boxes, s, o, d, k, tfar[0] if one else tfar[k]):
                dist[k] = tfar[0] if one else tfar[k]  # what Embree leaves in a missed ray's tfar
                prim[k] = -1
                continue
            # RTCRayHit: org, tnear, dir, time, tfar, mask, id, flags | Ng, u, v, primID, geomID, instID
            rec[0] = o[k, 0]
            rec[1] = o[k, 1]
            rec[2] = o[k, 2]
            rec[3] = 0.0
            rec[4] = d[k, 0]
            rec[5] = d[k, 1]
            rec[6] = d[k, 2]
            rec[7] = 0.0
            rec[8] = tfar[0] if one else tfar[k]
            rec_u[9] = 0xFFFFFFFF
            rec_u[10] = 0
            rec_u[11] = 0
            rec_u[17] = 0xFFFFFFFF
            rec_u[18] = 0xFFFFFFFF
            intersect1(scenes[s], p, 0)
            dist[k] = rec[8]
            prim[k] = np.int32(rec_u[17]) if rec_u[18] != 0xFFFFFFFF else np.int32(-1)

    return cast


def intersect_many(scenes: list, which: np.ndarray, origins: np.ndarray, directions: np.ndarray,
                   tfar: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """First hits of rays each cast into a scene of its own, in one compiled loop (GIL released).

    The actors' rays go to their prototypes' scenes this way: one call per chunk instead of one per
    prototype, with no sort to group them. Each ray's hit is the one :meth:`Scene.intersect` gives it: a ray
    whose segment ``[0, tfar]`` passes outside its scene's bounding box (grown by :data:`BOX_MARGIN_M`) is
    not cast, since Embree can only report a triangle inside that box and leaves a missed ray's ``tfar``
    as it was (on the default town with 120 cars, ~9.4 k of the ~29.5 k actor rays of a physical sweep).

    Parameters
    ----------
    scenes : list of Scene
    which : (n,) int64
        Index into ``scenes`` of each ray's scene.
    origins, directions : (n, 3) float32, C-contiguous
        In each ray's scene frame; unit directions, metres.
    tfar : (n,) float32
        Farthest distance to report per ray, metres.

    Returns
    -------
    distance : (n,) float32
        ``tfar`` where nothing was hit.
    prim : (n,) int32
        Face row in the ray's scene, -1 where nothing was hit.
    """
    dist = np.empty(len(origins), np.float32)
    prim = np.empty(len(origins), np.int32)
    ptrs = np.array([sc._ptr for sc in scenes], np.uint64)
    boxes = np.array([sc.box for sc in scenes], np.float64)
    _kernel()(ptrs, np.ascontiguousarray(which, np.int64), origins, directions, tfar, boxes, dist, prim)
    return dist, prim


_FIRST = np.zeros(1, np.int64)  # every ray into the first (only) scene
_NO_BOXES = np.zeros((0, 6), np.float64)  # every ray cast (no bounding-box test)


class Scene:
    """One Embree scene over one triangle soup, default (medium) build quality.

    Parameters
    ----------
    vertices : (V, 3) float32
        Vertex positions in the caster's frame, metres. Shared with Embree (kept alive here).
    faces : (F, 3) int
        Vertex indices; the primitive id of a hit is the row.
    robust : bool
        Watertight triangle tests (``RTC_SCENE_FLAG_ROBUST``, as ``embreex``: the same bits as its hits),
        or Embree's fast test (default; see the module docstring).
    """

    def __init__(self, vertices: np.ndarray, faces: np.ndarray, robust: bool = False):
        lib = _library()
        self._cast = _kernel()
        # Embree reads the last float3 with a 16-byte load: one float of padding past the end
        self._v = np.zeros(3 * len(vertices) + 1, np.float32)
        self._v[:-1] = np.asarray(vertices, np.float32).ravel()
        faces = np.ascontiguousarray(faces)
        # non-negative int32 rows are the same bytes as uint32: a view, not a second index buffer
        self._f = faces.view(np.uint32) if faces.dtype == np.int32 else faces.astype(np.uint32)
        dev = _device()
        self._lib, self._ptr = lib, lib.rtcNewScene(dev)
        self._one = np.array([self._ptr], np.uint64)  # what the cast loop takes: an array of scenes
        v = self._v[:-1].reshape(-1, 3).astype(np.float64)
        #: bounding box of the vertices Embree holds, grown by BOX_MARGIN_M (lo xyz, hi xyz)
        self.box = np.concatenate([v.min(0) - BOX_MARGIN_M, v.max(0) + BOX_MARGIN_M]) if len(v) else np.zeros(6)
        lib.rtcSetSceneFlags(self._ptr, _ROBUST if robust else 0)
        geom = lib.rtcNewGeometry(dev, _TRIANGLE)
        lib.rtcSetSharedGeometryBuffer(geom, _VERTEX, 0, _FLOAT3, self._v.ctypes.data, 0, 12, len(vertices))
        lib.rtcSetSharedGeometryBuffer(geom, _INDEX, 0, _UINT3, self._f.ctypes.data, 0, 12, len(self._f))
        lib.rtcCommitGeometry(geom)
        lib.rtcAttachGeometry(self._ptr, geom)
        lib.rtcReleaseGeometry(geom)
        lib.rtcCommitScene(self._ptr)
        err = lib.rtcGetDeviceError(dev)
        if err:
            raise RuntimeError(f"Embree failed to build the scene (error code {err})")

    @property
    def vertices(self) -> np.ndarray:
        """(V, 3) float32 view of the vertices Embree reads (without the padding float); do not write."""
        return self._v[:-1].reshape(-1, 3)

    def __del__(self):
        ptr, self._ptr = getattr(self, "_ptr", None), None
        if ptr:
            self._lib.rtcReleaseScene(ptr)

    def intersect(self, origins: np.ndarray, directions: np.ndarray, tfar: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """First hits of rays (GIL released during the cast).

        Parameters
        ----------
        origins, directions : (n, 3) float32, C-contiguous
            Ray origins in the scene's frame and unit directions, metres.
        tfar : (1,) or (n,) float32
            Farthest distance to report, one for all rays or one per ray, metres.

        Returns
        -------
        distance : (n,) float32
            Distance of the hit; ``tfar`` where nothing was hit.
        prim : (n,) int32
            Face row of the hit, -1 where nothing was hit.
        """
        dist = np.empty(len(origins), np.float32)
        prim = np.empty(len(origins), np.int32)
        self._cast(self._one, _FIRST, origins, directions, tfar, _NO_BOXES, dist, prim)
        return dist, prim
