"""Convex hulls with the exact output of ``trimesh.convex.convex_hull``, without its mesh object.

The label proxies (:func:`generator.geometry.primitives.convex_hull`) need a hull's vertices,
faces and angle-weighted vertex normals. ``trimesh.convex.convex_hull`` computes them in three
stages: qhull (``Qt QbB Pp``), its own winding repair (faces flipped to face away from the
area-weighted centroid), then a :class:`trimesh.Trimesh` with ``process=True`` and
``fix_normals``, whose construction, vertex merging and graph checks cost as much as qhull
itself for a hull of a few hundred points -- and a town makes ~200 new hulls.

:func:`hull_arrays` runs the first two stages with trimesh's own functions, in trimesh's order,
and the third's arithmetic (``weighted_vertex_normals`` of the stored face normals and the
corner angles) directly. What the ``Trimesh`` stage *could* change is checked instead of
done; when any check fails (qhull needs joggling, two hull vertices within merging distance,
stored normals trimesh would reject, a winding trimesh would repair or an inside-out solid),
the hull is computed by trimesh itself. So the arrays are trimesh's, bit for bit, either way
(``tests/test_geometry_hull.py`` holds the two equal on the asset families' hulls).
"""

from __future__ import annotations

import logging

import numpy as np

from generator.geometry.transforms import cross

log = logging.getLogger(__name__)

#: hull vertices closer than this (metres, ``1e3 * trimesh.constants.tol.merge``) in every coordinate
#: go the trimesh way: its vertex merge (rounding to ``tol.merge``) might join them
MERGE_GUARD = 1e3 * 1e-8


def _by_trimesh(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    import trimesh

    hull = trimesh.convex.convex_hull(points)
    return np.asarray(hull.vertices, np.float64), np.asarray(hull.faces, np.int64), \
        np.asarray(hull.vertex_normals, np.float64)


def _closed_and_consistent(faces: np.ndarray, n_vertices: int) -> bool:
    """Every directed edge once and its reverse once: what ``trimesh.graph.is_watertight`` calls
    watertight (each edge in exactly two faces) with a consistent winding (opposite directions)."""
    a = faces.reshape(-1)
    b = faces[:, [1, 2, 0]].reshape(-1)
    edges = np.sort(a * n_vertices + b)
    if len(edges) > 1 and not np.all(edges[1:] != edges[:-1]):
        return False
    return bool(np.array_equal(np.sort(b * n_vertices + a), edges))


def _fast(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """trimesh's hull arithmetic without the Trimesh object, or None where it would differ."""
    # imported here, not with the module: trimesh and scipy.spatial take ~0.7 s to import, and most
    # processes that import the geometry never make a hull
    from scipy.spatial import ConvexHull, QhullError, cKDTree
    from trimesh import geometry as tm_geometry
    from trimesh import triangles as tm_triangles
    from trimesh import util as tm_util
    from trimesh.constants import tol
    from trimesh.convex import QHULL_DEFAULT

    try:
        hull = ConvexHull(points, qhull_options=str(QHULL_DEFAULT))
    except QhullError:
        return None                               # trimesh retries with joggle ("QJ")
    # -- trimesh.convex.convex_hull, step by step ------------------------------------------
    vid = np.sort(hull.vertices)
    mask = np.zeros(len(hull.points), dtype=np.int64)
    mask[vid] = np.arange(len(vid))
    faces = mask[hull.simplices].copy()
    vertices = hull.points[vid].copy()
    crosses = tm_triangles.cross(vertices[faces])
    normals, valid = tm_util.unitize(crosses, check_valid=True)
    faces = faces[valid]
    crosses = crosses[valid]
    area = tm_triangles.area(crosses=crosses)
    centre = vertices[faces].mean(axis=1)
    if len(faces) < 4 or not area.sum() > 0:
        return None
    centroid = np.average(centre, weights=area, axis=0)
    backwards = tm_util.diagonal_dot(normals, centre - centroid) < 0.0
    faces[backwards] = np.fliplr(faces[backwards])
    normals[backwards] *= -1.0
    # -- what Trimesh(process=True) and fix_normals would change: checked, not done ----------
    if not np.all(np.isfinite(vertices)):
        return None
    pairs = cKDTree(vertices).query_pairs(MERGE_GUARD, p=np.inf)
    if pairs:                                     # merge_vertices might join two of them
        return None
    ptp = np.ptp(normals)
    check, ok = tm_triangles.normals(vertices[faces[:20]])
    compare = np.zeros((len(ok), 3))
    compare[ok] = check
    head = normals[:20]
    # np.allclose(compare, head) for finite arrays (anything else fails, and falls back)
    if not np.isfinite(ptp) or ptp < tol.merge or compare.shape != head.shape \
            or not np.all(np.abs(compare - head) <= 1e-08 + 1e-05 * np.abs(head)):
        return None                               # the face_normals setter would ignore ours
    if not _closed_and_consistent(faces, len(vertices)):
        return None                               # fix_winding would traverse and flip
    tri = vertices[faces]
    volume = np.einsum("ij,ij->i", tri[:, 0], cross(tri[:, 1], tri[:, 2])).sum() / 6.0
    if not volume > 0:
        return None                               # fix_inversion would invert
    angles = tm_triangles.angles(tri)
    vertex_normals = tm_geometry.weighted_vertex_normals(len(vertices), faces, normals, angles)
    return vertices, faces, vertex_normals


def hull_arrays(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Convex hull of ``points`` as ``trimesh.convex.convex_hull(points)`` gives it.

    Parameters
    ----------
    points : (n, 3) float64
        Any frame, metres.

    Returns
    -------
    vertices : (v, 3) float64
        The hull's vertices (input points, in input order).
    faces : (f, 3) int64
        Wound counter-clockwise seen from outside.
    vertex_normals : (v, 3) float64
        Unit, angle-weighted mean of the adjacent face normals (``Trimesh.vertex_normals``).
    """
    points = np.asarray(points, dtype=np.float64)
    out = _fast(points)
    if out is None:
        log.debug("hull of %d points: trimesh's own path", len(points))
        return _by_trimesh(points)
    return out
