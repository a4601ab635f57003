"""Ray casting against the SceneModel's real triangles, behind one small interface.

The only backend is Embree 4, the library ``embreex`` installs: called directly
(:mod:`generator.lidar.embree_native`: ~8x faster builds, ~1.3-1.5x faster sweeps with its fast,
non-watertight triangle test; the same hits with ``robust=True``) and through ``embreex.run`` where
that library cannot be loaded. A caster is built ONCE per
scene and reused for every frame.

Precision: Embree works in float32. The vertices are re-centred once, in float64, on the
centre of the scene's bounding box before the cast to float32, and every ray origin is
translated into that frame (float64 subtraction, then float32). Coordinates therefore
stay within half the town's extent (about +-150 m for a 4x4 town, float32 spacing
1.5e-5 m there), and the hit distance is measured from the ray origin, so ranges keep
sub-millimetre precision anywhere in the town (a test casts a town 3 km from the origin).
Re-centring on each sensor position would need a BVH rebuild per frame: measured on the
default 3x3 town (665k triangles, 2 cores) the build takes ~0.5 s, a whole sweep ~0.02 s,
so a per-frame rebuild would make the LiDAR 25-40x slower for no precision gain at these
extents (``bench/lidar_throughput.py`` prints both).

Threads: both backends release the GIL during a cast, so callers split rays across a
``ThreadPoolExecutor`` (see :mod:`generator.lidar.scan`).
"""

from __future__ import annotations

import time
from typing import Protocol

import numpy as np

from generator.lidar import embree_native


class RayCaster(Protocol):
    """What the scanner needs from a backend."""

    #: (3,) float64 re-centring point: ``intersect_local`` takes origins minus this.
    center: np.ndarray

    def intersect_local(self, origins: np.ndarray, directions: np.ndarray, max_distance: float,
                        mark_misses: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """First hits of re-centred float32 rays; see :meth:`EmbreeCaster.intersect_local`."""

    def intersect(
        self, origins: np.ndarray, directions: np.ndarray, max_distance: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """First hits of rays; see :meth:`EmbreeCaster.intersect`."""

    def triangle_corners(self) -> np.ndarray:
        """(F, 3, 3) float32 corners of every face, re-centred; see :meth:`EmbreeCaster.triangle_corners`."""

    @property
    def direct_scene(self) -> embree_native.Scene | None:
        """The Embree scene the direct calls cast into (None when ``embreex.run`` casts); see
        :attr:`EmbreeCaster.direct_scene`."""

    @property
    def face_normals(self) -> np.ndarray:
        """(F, 3) float32 unit face normals, world frame."""


def _unit_normals(tri: np.ndarray) -> np.ndarray:
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    norm = np.linalg.norm(n, axis=1, keepdims=True)
    return np.divide(n, norm, out=np.zeros_like(n), where=norm > 0).astype(np.float32)


class EmbreeCaster:
    """An Embree BVH over one triangle soup, re-centred for float32.

    Parameters
    ----------
    vertices : (V, 3) float32 or float64
        World frame, metres.
    faces : (F, 3) integer
        Vertex indices; the primitive id of a hit is the row in ``faces``.
    center : (3,) float64, optional
        Re-centring point (default: centre of the vertices' bounding box).
    native : bool, optional
        Cast through :mod:`generator.lidar.embree_native` (default: when its library loads) or
        through ``embreex.run`` (False).
    robust : bool, optional
        Direct calls only: watertight triangle tests, the same bits as ``embreex.run`` (whose scenes are
        always watertight), or Embree's fast test (default: 1.29x faster casts; about one ray in a million
        meets a neighbouring triangle or slips through a shared edge, see :mod:`~generator.lidar.embree_native`).

    Attributes
    ----------
    center : (3,) float64
    build_seconds : float
        Wall time of the BVH build.
    native : bool
        Which backend casts.
    """

    def __init__(self, vertices: np.ndarray, faces: np.ndarray, center: np.ndarray | None = None,
                 native: bool | None = None, robust: bool = False):
        v64 = np.asarray(vertices, np.float64).reshape(-1, 3)
        f = np.ascontiguousarray(np.asarray(faces).reshape(-1, 3), np.int32)
        if len(f) == 0:
            raise ValueError("cannot build a caster over a scene without triangles")
        self.center = (v64.min(0) + v64.max(0)) / 2.0 if center is None else np.asarray(center, np.float64)
        local = np.ascontiguousarray(v64 - self.center, np.float32)
        self.n_faces = len(f)
        self._local, self._triangles, self._corners = local, f, None
        self._normals = _unit_normals(v64[f])
        self.native = embree_native.available() if native is None else native
        t0 = time.perf_counter()
        if self.native:
            self._scene = embree_native.Scene(local, f, robust=robust)
            self._local = self._scene.vertices  # Embree's padded copy serves us too: one copy, not two
        else:
            from embreex import rtcore_scene
            from embreex.mesh_construction import TriangleMesh

            self._scene = rtcore_scene.EmbreeScene()
            TriangleMesh(self._scene, local, f)
        self.build_seconds = time.perf_counter() - t0

    @classmethod
    def from_scene(cls, scene) -> EmbreeCaster:
        """A caster over ``scene.vertices`` / ``scene.faces`` (the real geometry, never the label proxies)."""
        return cls(scene.vertices, scene.faces)

    @property
    def direct_scene(self) -> embree_native.Scene | None:
        """The Embree scene the direct calls cast into (None when ``embreex.run`` casts)."""
        return self._scene if self.native else None

    @property
    def face_normals(self) -> np.ndarray:
        """(F, 3) float32 unit normals per face, world frame (zero for degenerate faces)."""
        return self._normals

    def triangle_corners(self) -> np.ndarray:
        """(F, 3, 3) float32 corners of every face as Embree holds them (world minus :attr:`center`, metres).

        Built on the first call and kept (``12 * 3 * F`` bytes: only the physical return model asks).
        """
        if self._corners is None:
            self._corners = self._local[self._triangles]
        return self._corners

    def intersect_local(self, origins: np.ndarray, directions: np.ndarray,
                        max_distance: float | np.ndarray, mark_misses: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """First hits of rays whose origins are already re-centred (``world - center``).

        Parameters
        ----------
        origins : (n, 3) float32
            Ray origins minus :attr:`center`, metres.
        directions : (n, 3) float32
            Unit directions, world axes.
        max_distance : float or (n,) float32
            Hits farther than this are misses, metres (per ray: only hits nearer than a known one).
        mark_misses : bool
            Set the distance of a miss to ``inf`` (False: it keeps ``max_distance``, for a
            caller that marks them in its own pass over the rays).

        Returns
        -------
        distance : (n,) float32
            Distance along the ray to the hit, metres (``inf`` on a miss).
        prim : (n,) int32
            Row of the hit face (-1 on a miss).
        """
        o = np.ascontiguousarray(origins, np.float32)
        d = np.ascontiguousarray(directions, np.float32)
        if self.native:
            dist, prim = self._scene.intersect(o, d, np.asarray(max_distance, np.float32).reshape(-1))
        else:  # a fresh tfar array every call: embreex writes the hit distances into it
            out = self._scene.run(o, d, dists=np.full(len(o), max_distance, np.float32), output=1)
            prim, dist = out["primID"], out["tfar"]
        if mark_misses:
            dist[prim < 0] = np.inf
        return dist, prim

    def intersect(
        self, origins: np.ndarray, directions: np.ndarray, max_distance: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """First hit of every ray.

        Parameters
        ----------
        origins : (n, 3) float64
            World frame, metres.
        directions : (n, 3) float
            Unit directions, world frame.
        max_distance : float
            Hits farther than this are misses, metres.

        Returns
        -------
        distance : (n,) float32
            Distance along the ray to the hit, metres (``inf`` on a miss).
        prim : (n,) int32
            Row of the hit face in ``faces`` (-1 on a miss).
        """
        return self.intersect_local(np.asarray(origins, np.float64) - self.center, directions, max_distance)

    def run_raw(self, origins_local: np.ndarray, directions: np.ndarray) -> dict:
        """The backend's plain cast of float32 rays already in the re-centred frame (benchmarks).

        ``{"tfar": (n,) float32, "primID": (n,) int32}``, as ``EmbreeScene.run(..., output=1)`` gives.
        """
        if self.native:
            dist, prim = self._scene.intersect(origins_local, directions, np.full(1, np.inf, np.float32))
            return {"tfar": dist, "primID": prim}
        return self._scene.run(origins_local, directions, output=1)


#: Backends by name (dispatch by table; Embree is the only one shipped).
BACKENDS = {"embree": EmbreeCaster.from_scene}


def make_caster(scene, backend: str = "embree") -> RayCaster:
    """A caster over ``scene``'s real triangles with the named backend."""
    try:
        return BACKENDS[backend](scene)
    except KeyError:
        raise ValueError(f"unknown ray-casting backend {backend!r}; known: {', '.join(BACKENDS)}") from None
