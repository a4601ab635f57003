"""Mesh primitives assets are built from: boxes, slabs, cylinders, tubes, lofts, polygons...

Every primitive takes a native class (name or id, ``generator/labels/classes.yaml``) and a
material (name or id, ``generator/materials.yaml``) and returns a
:class:`generator.geometry.mesh.Mesh` in metres, z up, faces wound counter-clockwise seen
from outside.
"""

from __future__ import annotations

import functools

import numpy as np

from generator.geometry.faces import cylinder_parts, fan_faces, loft_faces
from generator.geometry.hull import hull_arrays
from generator.geometry.mesh import Mesh
from generator.geometry.transforms import cross
from generator.labels import class_table
from generator.materials import material_table


def resolve_ids(cls: str | int, material: str | int) -> tuple[int, int]:
    """(class id, material id) from names or ids (``classes.yaml``, ``materials.yaml``; both tables
    are read once per process, so the answer is remembered: a town asks ~50 000 times)."""
    try:
        return _resolve_ids(cls, material)
    except TypeError:                            # an unhashable id (a 0-d array): not remembered
        return _resolve_ids.__wrapped__(cls, material)


@functools.lru_cache(maxsize=4096)
def _resolve_ids(cls: str | int, material: str | int) -> tuple[int, int]:
    c = class_table().id(cls) if isinstance(cls, str) else int(cls)
    m = material_table().id(material) if isinstance(material, str) else int(material)
    return c, m


_UNIT_BOX_VERTICES = np.array([[0, 0, 0], [0, 0, 1], [0, 1, 0], [0, 1, 1], [1, 0, 0], [1, 0, 1], [1, 1, 0], [1, 1, 1]],
                              np.float64)
_UNIT_BOX_FACES = np.array([[1, 3, 0], [4, 1, 0], [0, 3, 2], [2, 4, 0], [1, 7, 3], [5, 1, 4], [5, 7, 1], [3, 7, 2],
                            [6, 4, 2], [2, 7, 6], [6, 5, 4], [7, 5, 6]], np.int64)


def box(size: tuple[float, float, float], cls: str | int, material: str | int,
        center: tuple[float, float, float] = (0.0, 0.0, 0.0), bottom: bool = True) -> Mesh:
    """An axis-aligned box of ``size`` (x, y, z) metres centred on ``center``.

    ``bottom=False`` leaves out the two bottom triangles (boxes resting on the ground
    need no hidden floor).
    """
    # trimesh's unit box, vertex and face order kept (towns built before stay byte-identical),
    # without building a Trimesh (normals, caches): the town builds ~15k boxes
    vertices = _UNIT_BOX_VERTICES - 0.5
    vertices *= np.asarray(size, dtype=np.float64)
    faces = _UNIT_BOX_FACES
    if not bottom:
        centroids_z = vertices[faces].mean(1)[:, 2]
        faces = faces[centroids_z > -size[2] / 2 + 1e-9]
    c, m = resolve_ids(cls, material)
    return Mesh(vertices + np.asarray(center, float), faces, c, m)


def slab(x0: float, y0: float, x1: float, y1: float, z0: float, z1: float, cls: str | int,
         material: str | int, bottom: bool = False) -> Mesh:
    """A box spanning [x0, x1] x [y0, y1] x [z0, z1] (ground slabs, curbs)."""
    return box((x1 - x0, y1 - y0, z1 - z0), cls, material, ((x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2), bottom)


def rect(x0: float, y0: float, x1: float, y1: float, z: float, cls: str | int, material: str | int) -> Mesh:
    """A flat upward-facing rectangle at height ``z`` (markings, ground patches)."""
    v = np.array([[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]], float)
    c, m = resolve_ids(cls, material)
    return Mesh(v, [[0, 1, 2], [0, 2, 3]], c, m)


def quad(corners: np.ndarray, cls: str | int, material: str | int) -> Mesh:
    """A planar quad from four (x, y, z) corners in counter-clockwise order (seen from its front)."""
    c, m = resolve_ids(cls, material)
    return Mesh(np.asarray(corners, float), [[0, 1, 2], [0, 2, 3]], c, m)


def cylinder(radius: float, height: float, cls: str | int, material: str | int, sections: int = 8,
             z0: float = 0.0, radius_top: float | None = None, caps: bool = True) -> Mesh:
    """A vertical (optionally tapered) cylinder from ``z0`` to ``z0 + height`` around the z axis."""
    rt = radius if radius_top is None else radius_top
    ring, faces = cylinder_parts(int(sections), bool(caps))
    k = len(ring)
    v = np.empty((2 * k + (2 if caps else 0), 3))
    v[:k, :2] = ring * radius
    v[:k, 2] = z0
    v[k:2 * k, :2] = ring * rt
    v[k:2 * k, 2] = z0 + height
    if caps:
        v[2 * k:] = [[0, 0, z0], [0, 0, z0 + height]]
    c, m = resolve_ids(cls, material)
    return Mesh(v, faces.copy(), c, m)


def icosphere(radius: float, cls: str | int, material: str | int, subdivisions: int = 1,
              center: tuple[float, float, float] = (0.0, 0.0, 0.0),
              scale: tuple[float, float, float] = (1.0, 1.0, 1.0)) -> Mesh:
    """An icosphere (20 * 4**subdivisions triangles), optionally scaled per axis into an ellipsoid."""
    vertices, faces = _unit_icosphere(int(subdivisions), float(radius))
    c, m = resolve_ids(cls, material)
    return Mesh(vertices * np.asarray(scale, float) + np.asarray(center, float), faces.copy(), c, m)


@functools.lru_cache(maxsize=64)
def _unit_icosphere(subdivisions: int, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """trimesh's icosphere arrays (read-only), made once per (subdivisions, radius): trees and hedges
    ask for a thousand identical ones per town."""
    import trimesh  # imported on first use (~0.7 s with scipy)

    tm = trimesh.creation.icosphere(subdivisions=subdivisions, radius=radius)
    vertices, faces = np.array(tm.vertices, np.float64), np.array(tm.faces, np.int64)
    vertices.setflags(write=False)
    faces.setflags(write=False)
    return vertices, faces


def prism(polygon: np.ndarray, z0: float, z1: float, cls: str | int, material: str | int,
          top_material: str | int | None = None, bottom: bool = False) -> Mesh:
    """Extrude a simple counter-clockwise polygon ((k, 2) metres) from ``z0`` to ``z1``.

    Sides get ``material``; the top cap ``top_material`` (default ``material``).
    """
    poly = np.asarray(polygon, float)
    k = len(poly)
    tris = triangulate(poly)
    v = np.concatenate([np.c_[poly, np.full(k, z0)], np.c_[poly, np.full(k, z1)]])
    i = np.arange(k)
    j = (i + 1) % k
    sides = np.concatenate([np.stack([i, j, j + k], 1), np.stack([i, j + k, i + k], 1)])
    c, m = resolve_ids(cls, material)
    mt = m if top_material is None else resolve_ids(cls, top_material)[1]
    faces = [sides, tris + k]
    mats = [np.full(len(sides), m), np.full(len(tris), mt)]
    if bottom:
        faces.append(tris[:, ::-1])
        mats.append(np.full(len(tris), m))
    return Mesh(v, np.concatenate(faces), c, np.concatenate(mats))


def triangulate(poly: np.ndarray) -> np.ndarray:
    """Ear-clipping triangulation of a simple counter-clockwise polygon: (k-2, 3) int indices."""
    idx = list(range(len(poly)))
    out = []
    guard = 0
    while len(idx) > 3 and guard < 10000:
        guard += 1
        n = len(idx)
        for t in range(n):
            a, b, c = idx[(t - 1) % n], idx[t], idx[(t + 1) % n]
            pa, pb, pc = poly[a], poly[b], poly[c]
            cross = (pb[0] - pa[0]) * (pc[1] - pa[1]) - (pb[1] - pa[1]) * (pc[0] - pa[0])
            if cross <= 1e-12:
                continue
            others = [poly[o] for o in idx if o not in (a, b, c)]
            if any(_in_triangle(p, pa, pb, pc) for p in others):
                continue
            out.append((a, b, c))
            idx.pop(t)
            break
        else:
            raise ValueError("polygon is not simple or not counter-clockwise")
    out.append(tuple(idx))
    return np.array(out, np.int64)


def _in_triangle(p, a, b, c) -> bool:
    d1 = (p[0] - b[0]) * (a[1] - b[1]) - (a[0] - b[0]) * (p[1] - b[1])
    d2 = (p[0] - c[0]) * (b[1] - c[1]) - (b[0] - c[0]) * (p[1] - c[1])
    d3 = (p[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (p[1] - a[1])
    neg = (d1 < 0) or (d2 < 0) or (d3 < 0)
    pos = (d1 > 0) or (d2 > 0) or (d3 > 0)
    return not (neg and pos)


def convex_hull(mesh: Mesh, cls: str | int, inflate: float = 0.02) -> Mesh:
    """Convex hull of ``mesh``'s vertices pushed out by ``inflate`` metres (a label proxy).

    The hull is inflated so that it contains every vertex of the object strictly and
    wins the depth test against the object's own surface in the label pass.
    """
    vertices, faces, normals = hull_arrays(mesh.vertices)  # trimesh's hull, bit for bit, faster
    c, _ = resolve_ids(cls, "default")
    return Mesh(vertices + normals * inflate, faces, c, 0)


# -- primitives added for the asset families (additive; nothing above changed) ---------------

def _frame(axis: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors (u, v) with (u, v, axis) a right-handed orthonormal frame."""
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    helper = np.array([0.0, 0.0, 1.0]) if abs(axis[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    u = cross(helper, axis)
    u /= np.linalg.norm(u)
    return u, cross(axis, u)


def tube(p0: tuple[float, float, float], p1: tuple[float, float, float], radius: float, cls: str | int,
         material: str | int, radius1: float | None = None, sections: int = 8, caps: bool = True) -> Mesh:
    """A (tapered) cylinder from point ``p0`` (radius ``radius``) to ``p1`` (radius ``radius1``).

    Parameters
    ----------
    p0, p1 : (3,) float
        End centres, metres, local frame.
    radius, radius1 : float
        End radii, metres (``radius1`` defaults to ``radius``); both must be > 0.
    sections : int
        Number of sides.
    caps : bool
        Close both ends with a fan.
    """
    p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
    axis = p1 - p0
    length = float(np.linalg.norm(axis))
    u, v = _frame(axis)
    w = axis / length
    base = cylinder(radius, length, cls, material, sections, 0.0, radius1, caps)
    rot = np.stack([u, v, w], 1)
    return Mesh(base.vertices @ rot.T + p0, base.faces, base.face_class, base.face_material)


def loft(rings: np.ndarray, cls: str | int, material: str | int, caps: bool = True) -> Mesh:
    """Skin a sequence of closed rings with quads (car bodies, torsos, trunks).

    Parameters
    ----------
    rings : (s, k, 3) float
        ``s`` rings of ``k`` points each, metres; point ``i`` of one ring joins point ``i`` of
        the next. Each ring must be star-shaped around its centroid (convex is enough).
    caps : bool
        Close the first and last ring with a fan around the ring centroid.

    Returns
    -------
    Mesh
        Faces oriented outward (away from the local ring centroid), whatever the ring order.
    """
    rings = np.asarray(rings, float)
    s, k, _ = rings.shape
    v = rings.reshape(-1, 3)
    i = np.arange(k)
    j = (i + 1) % k
    faces = loft_faces(s, k).copy()
    centres = rings.mean(1)
    tri = v[faces]
    normal = cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    ring_of_face = faces[:, 0] // k
    out = tri.mean(1) - 0.5 * (centres[ring_of_face] + centres[np.minimum(ring_of_face + 1, s - 1)])
    if np.sum(np.einsum("ij,ij->i", normal, out)) < 0:
        faces = faces[:, ::-1]
    if caps:
        c0, c1 = len(v), len(v) + 1
        v = np.concatenate([v, centres[[0, -1]]])
        # orient each cap away from the neighbouring ring
        cap0 = np.stack([np.full(k, c0), j, i], 1)
        cap1 = np.stack([np.full(k, c1), (s - 1) * k + i, (s - 1) * k + j], 1)
        for cap, inward in ((cap0, centres[min(1, s - 1)] - centres[0]), (cap1, centres[max(s - 2, 0)] - centres[-1])):
            t = v[cap]
            n = cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]).sum(0)
            if np.dot(n, inward) > 0:
                cap[:] = cap[:, ::-1]
        faces = np.concatenate([faces, cap0, cap1])
    c, m = resolve_ids(cls, material)
    return Mesh(v, faces, c, m)


def polygon(points: np.ndarray, cls: str | int, material: str | int,
            normal: tuple[float, float, float] | None = None) -> Mesh:
    """A planar convex polygon from (k, 3) points, fan-triangulated.

    If ``normal`` is given the faces are oriented to face it; otherwise the point order
    (counter-clockwise seen from the front) decides.
    """
    p = np.asarray(points, float)
    faces = fan_faces(len(p))
    if normal is not None:
        n = cross(p[faces[:, 1]] - p[faces[:, 0]], p[faces[:, 2]] - p[faces[:, 0]]).sum(0)
        if np.dot(n, normal) < 0:
            faces = faces[:, ::-1]
    c, m = resolve_ids(cls, material)
    return Mesh(p, faces.copy(), c, m)


def disc(center: tuple[float, float, float], normal: tuple[float, float, float], radius: float,
         cls: str | int, material: str | int, sections: int = 12) -> Mesh:
    """A flat regular ``sections``-gon of circumradius ``radius`` facing ``normal``."""
    n = np.asarray(normal, float) / np.linalg.norm(normal)
    u, v = _frame(n)
    a = np.linspace(0, 2 * np.pi, sections, endpoint=False)
    pts = np.asarray(center, float) + radius * (np.cos(a)[:, None] * u + np.sin(a)[:, None] * v)
    return polygon(pts, cls, material, normal=n)


def quads(corners: np.ndarray, cls: str | int, materials, normals: np.ndarray | None = None) -> Mesh:
    """Many planar quads at once (facades with hundreds of windows).

    Parameters
    ----------
    corners : (n, 4, 3) float
        Corners of each quad in order around it, metres.
    materials : str, int or sequence of (str or int), length n
        One material for all quads or one per quad.
    normals : (n, 3) float, optional
        Direction each quad should face; quads wound the other way are flipped. Without it
        the corner order decides (counter-clockwise seen from the front).
    """
    corners = np.asarray(corners, float).reshape(-1, 4, 3)
    n = len(corners)
    base = 4 * np.arange(n)[:, None]
    tri_a = base + np.array([0, 1, 2])
    tri_b = base + np.array([0, 2, 3])
    if normals is not None:
        nq = cross(corners[:, 2] - corners[:, 0], corners[:, 3] - corners[:, 1])
        flip = np.einsum("ij,ij->i", nq, np.asarray(normals, float).reshape(-1, 3)) < 0
        tri_a[flip] = tri_a[flip][:, ::-1]
        tri_b[flip] = tri_b[flip][:, ::-1]
    faces = np.stack([tri_a, tri_b], 1).reshape(-1, 3)
    c, _ = resolve_ids(cls, "default")
    if isinstance(materials, (str, int, np.integer)):
        mats = np.full(n, resolve_ids(cls, materials)[1])
    else:
        table = {m: resolve_ids(cls, m)[1] for m in set(materials)}  # a few names, thousands of quads
        mats = np.array([table[m] for m in materials], np.int64)
    return Mesh(corners.reshape(-1, 3), faces, c, np.repeat(mats, 2))
