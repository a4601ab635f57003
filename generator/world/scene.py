"""SceneModel: the assembled scene, the single source of truth for geometry and labels.

Blender renders it (``generator.blender``) and Embree ray-casts it (``generator.lidar``);
both read the same prototypes and transforms, so the camera and the LiDAR see the same
triangles. Pure numpy: nothing here imports Blender.

Frames and units: world frame, metres, z up, x east, y north; the road surface is at
z = 0. Angles in radians, yaw counter-clockwise from +x.
"""

from __future__ import annotations

import functools
import hashlib
from dataclasses import dataclass, field

import numpy as np

from generator.geometry import Mesh, apply
from generator.geometry.boxes import OrientedBox


@dataclass
class SceneObject:
    """One placed object: a prototype mesh under a transform.

    Attributes
    ----------
    index : int
        Position in :attr:`SceneModel.objects`.
    name : str
        Unique, e.g. ``"car_0012"`` (safe as a file or Blender name).
    kind : str
        Asset family (``"car"``, ``"tree"``, ``"road_surface"``...).
    cls : str
        Main native class of the object (a tree's is ``tree_crown``...).
    instance_id : int
        Instance id, 1..65535 for things, 0 for stuff (roads, sidewalks, terrain).
    prototype : str
        Key into :attr:`SceneModel.prototypes`; shared by repeated assets (instancing).
    transform : (4, 4) float64
        World-from-local transform.
    box : OrientedBox
        Oriented bounding box of the object's real geometry, world frame.
    proxy : str or None
        Key into :attr:`SceneModel.proxies` of the label-proxy hull, if the class policy gives one.
    attrs : dict
        Free per-object parameters for renderers, e.g. ``{"color": [r, g, b]}`` (0..1 floats).
    """

    index: int
    name: str
    kind: str
    cls: str
    instance_id: int
    prototype: str
    transform: np.ndarray
    box: OrientedBox
    proxy: str | None = None
    attrs: dict = field(default_factory=dict)


@dataclass
class Path:
    """A drivable path along lane centres.

    Attributes
    ----------
    name : str
    points : (n, 3) float64
        Lane-centre samples on the road surface, world frame, metres (about 1 m apart).
    headings : (n,) float64
        Driving direction at each sample, radians.
    s : (n,) float64
        Arc length from the first sample, metres.
    closed : bool
        True when the last sample connects back to the first (a loop).
    """

    name: str
    points: np.ndarray
    headings: np.ndarray
    s: np.ndarray
    closed: bool = False

    def length(self) -> float:
        """Total length in metres (including the closing segment of a loop)."""
        extra = float(np.linalg.norm(self.points[0] - self.points[-1])) if self.closed else 0.0
        return float(self.s[-1]) + extra

    def at(self, s: np.ndarray | float) -> tuple[np.ndarray, np.ndarray]:
        """Positions (k, 3) and headings (k,) at arc lengths ``s`` (metres; wrapped on loops)."""
        if not self.closed and isinstance(s, float):   # one vehicle's pose, every step of the traffic simulation
            return self._at_one(s)
        s = np.atleast_1d(np.asarray(s, np.float64))
        pts, hd, ss = self.points, self.headings, self.s
        if self.closed:
            pts = np.vstack([pts, pts[:1]])
            hd = np.append(hd, hd[0])
            ss = np.append(ss, self.length())
            s = np.mod(s, self.length())
        else:
            s = np.clip(s, 0.0, ss[-1])
        i = np.clip(np.searchsorted(ss, s, side="right") - 1, 0, len(ss) - 2)
        t = ((s - ss[i]) / np.maximum(ss[i + 1] - ss[i], 1e-12))[:, None]
        pos = pts[i] * (1 - t) + pts[i + 1] * t
        dh = np.angle(np.exp(1j * (hd[i + 1] - hd[i])))
        return pos, np.angle(np.exp(1j * (hd[i] + t[:, 0] * dh)))

    def _at_one(self, s: float) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`at` of one arc length on an open path: the same arithmetic on scalars (same bytes)."""
        pts, hd, ss = self.points, self.headings, self.s
        s = s if s > 0.0 else 0.0               # np.clip's order: max with the low end, then min with the high
        last = ss[-1]
        s = s if s < last else last
        i = min(max(int(ss.searchsorted(s, side="right")) - 1, 0), len(ss) - 2)
        gap = ss[i + 1] - ss[i]
        t = (s - ss[i]) / (gap if gap >= 1e-12 else 1e-12)
        pos = pts[i] * (1 - t) + pts[i + 1] * t
        dh = np.angle(np.exp(1j * (hd[i + 1] - hd[i])))
        return pos[None], np.atleast_1d(np.angle(np.exp(1j * (hd[i] + t * dh))))


@dataclass
class SceneModel:
    """The whole scene: prototypes, placed objects, label proxies and paths.

    Attributes
    ----------
    seed : int
        The spec's seed.
    spec_hash : str
        SHA-256 of the canonical spec JSON.
    bounds : (2, 2) float64
        Town extent [[xmin, ymin], [xmax, ymax]], metres.
    prototypes : dict of str to Mesh
        Meshes in local frames; objects reference them (repeated assets share one).
    proxies : dict of str to Mesh
        Convex-hull label proxies in the same local frames as their objects' prototypes.
    objects : list of SceneObject
    paths : list of Path
        Lane-following routes for cameras and the ego vehicle.

    The town the layout builds (:class:`generator.layout.town.Town`) is a SceneModel that also
    keeps the street grid, the asset library and, for streets crossing at an angle, the grid ->
    world map and the grid-frame scene.
    """

    seed: int
    spec_hash: str
    bounds: np.ndarray
    prototypes: dict[str, Mesh]
    proxies: dict[str, Mesh]
    objects: list[SceneObject]
    paths: list[Path]

    # -- flat triangle soup (what Embree casts against) --------------------------------------
    @functools.cached_property
    def _flat(self) -> dict[str, np.ndarray]:
        return _flatten(self.objects, self.prototypes, lambda o: o.prototype)

    @property
    def vertices(self) -> np.ndarray:
        """(V, 3) float32 world-frame vertices of the real geometry, metres."""
        return self._flat["vertices"]

    @property
    def faces(self) -> np.ndarray:
        """(F, 3) uint32 vertex indices."""
        return self._flat["faces"]

    @property
    def face_class(self) -> np.ndarray:
        """(F,) uint8 native class id per triangle."""
        return self._flat["face_class"]

    @property
    def face_material(self) -> np.ndarray:
        """(F,) uint16 material id per triangle."""
        return self._flat["face_material"]

    @property
    def face_instance(self) -> np.ndarray:
        """(F,) uint16 instance id per triangle (0 for stuff)."""
        return self._flat["face_instance"]

    @property
    def face_object(self) -> np.ndarray:
        """(F,) int32 index into :attr:`objects` per triangle."""
        return self._flat["face_object"]

    @functools.cached_property
    def _proxy_flat(self) -> dict[str, np.ndarray]:
        with_proxy = [o for o in self.objects if o.proxy is not None]
        return _flatten(with_proxy, self.proxies, lambda o: o.proxy)

    @property
    def proxy_arrays(self) -> dict[str, np.ndarray]:
        """The label proxies flattened like the real geometry (same keys as the flat soup)."""
        return self._proxy_flat

    # -- identity ------------------------------------------------------------------------
    def digest(self) -> str:
        """SHA-256 over every array and object record: equal digests mean identical scenes."""
        h = hashlib.sha256()
        for key in ("vertices", "faces", "face_class", "face_material", "face_instance", "face_object"):
            h.update(np.ascontiguousarray(self._flat[key]).tobytes())
        for key in ("vertices", "faces", "face_class"):
            h.update(np.ascontiguousarray(self._proxy_flat[key]).tobytes())
        for o in self.objects:
            h.update(repr((o.name, o.kind, o.cls, o.instance_id, o.prototype, o.proxy, o.box,
                           sorted(o.attrs.items()))).encode())
            h.update(np.ascontiguousarray(o.transform).tobytes())
        for p in self.paths:
            h.update(p.name.encode() + p.points.tobytes() + p.headings.tobytes())
        return h.hexdigest()

    def objects_of(self, cls: str) -> list[SceneObject]:
        """Objects whose main class is ``cls``."""
        return [o for o in self.objects if o.cls == cls]


def _flatten(objects: list[SceneObject], meshes: dict[str, Mesh], key) -> dict[str, np.ndarray]:
    verts, faces, fcls, fmat, finst, fobj = [], [], [], [], [], []
    offset = 0
    for o in objects:
        m = meshes[key(o)]
        verts.append(apply(o.transform, m.vertices).astype(np.float32))
        faces.append((m.faces + offset).astype(np.uint32))
        offset += len(m.vertices)
        fcls.append(m.face_class)
        fmat.append(m.face_material)
        finst.append(np.full(m.n_faces, o.instance_id, np.uint16))
        fobj.append(np.full(m.n_faces, o.index, np.int32))

    def cat(parts, shape, dtype):
        return np.concatenate(parts).astype(dtype, copy=False) if parts else np.zeros(shape, dtype)

    return {
        "vertices": cat(verts, (0, 3), np.float32),
        "faces": cat(faces, (0, 3), np.uint32),
        "face_class": cat(fcls, (0,), np.uint8),
        "face_material": cat(fmat, (0,), np.uint16),
        "face_instance": cat(finst, (0,), np.uint16),
        "face_object": cat(fobj, (0,), np.int32),
    }
