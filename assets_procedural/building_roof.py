"""Roofs for :mod:`assets_procedural.building`: flat with parapet, gable, hip.

All faces are class ``building``. Pitched roofs are thin solids (top, underside,
fascia) with eaves overhanging the walls, so they read from the street and from below.
"""

from __future__ import annotations

import numpy as np

from generator.geometry import Mesh, box, merge, polygon, pose, resolve_ids, triangulate

CLS = "building"
COPING_OUT = 0.05    #: the parapet coping overhangs the walls by this much, metres
COPING_H = 0.08      #: depth of the coping's lip, metres
UP = np.array([0.0, 0.0, 1.0])


def rectangle_of(poly: np.ndarray) -> tuple[float, float, float, float] | None:
    """(cx, cy, hx, hy) if ``poly`` ((k, 2) float) is an axis-aligned rectangle, else None."""
    if len(poly) != 4:
        return None
    lo, hi = poly.min(0), poly.max(0)
    on_corner = np.all(np.isclose(poly, lo) | np.isclose(poly, hi), axis=1)
    if not on_corner.all():
        return None
    c, h = (lo + hi) / 2, (hi - lo) / 2
    return float(c[0]), float(c[1]), float(h[0]), float(h[1])


def _offset_inward(poly: np.ndarray, t: float) -> np.ndarray:
    """(k, 2) float: the CCW polygon with every edge moved ``t`` metres inward (mitred corners)."""
    k = len(poly)
    d = np.roll(poly, -1, 0) - poly
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    n = np.stack([d[:, 1], -d[:, 0]], 1)              # outward normals
    c = np.einsum("ij,ij->i", n, poly) - t            # offset lines n_i . p = c_i
    out = np.empty_like(poly)
    for j in range(k):
        i = j - 1                                      # vertex j joins edge j-1 and edge j
        a = np.stack([n[i], n[j]])
        out[j] = np.linalg.solve(a, [c[i], c[j]])
    return out


def _inside(poly: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """(n,) bool: points strictly inside the polygon (crossing number)."""
    x, y = pts[:, 0:1], pts[:, 1:2]
    a, b = poly, np.roll(poly, -1, 0)
    cond = (a[:, 1] > y) != (b[:, 1] > y)
    xi = a[:, 0] + (y - a[:, 1]) * (b[:, 0] - a[:, 0]) / np.where(b[:, 1] == a[:, 1], 1, b[:, 1] - a[:, 1])
    return (np.sum(cond & (x < xi), axis=1) % 2) == 1


def flat_roof(rng: np.random.Generator, poly: np.ndarray, height: float, parapet: float, facade_mat: str,
              coping: str = "facade_concrete") -> Mesh:
    """Roof slab ``parapet`` below the wall top, parapet inner walls, a coping over the parapet that
    overhangs the walls by ``COPING_OUT`` (a lip ``COPING_H`` deep: the roof edge reads as a line from
    the street), rooftop boxes.

    Parameters
    ----------
    poly : (k, 2) float
        Cleaned CCW footprint, metres.
    height : float
        Top of the parapet (wall top), metres.
    """
    t = 0.25
    inner = _offset_inward(poly, t)
    zr = height - parapet
    k = len(poly)
    tris = triangulate(inner)
    parts = [Mesh(np.c_[inner, np.full(k, zr)], tris, *resolve_ids(CLS, "roof"))]
    for i in range(k):
        j = (i + 1) % k
        q0, q1, p0, p1 = inner[i], inner[j], poly[i], poly[j]
        inward = np.array([-(q1 - q0)[1], (q1 - q0)[0], 0.0])
        parts.append(polygon([[*q0, zr], [*q1, zr], [*q1, height], [*q0, height]], CLS, facade_mat, inward))
    outer = _offset_inward(poly, -COPING_OUT)
    zc = height - COPING_H
    for i in range(k):
        j = (i + 1) % k
        q0, q1, p0, p1, o0, o1 = inner[i], inner[j], poly[i], poly[j], outer[i], outer[j]
        out = np.array([(p1 - p0)[1], -(p1 - p0)[0], 0.0])
        parts.append(polygon([[*o0, height], [*o1, height], [*q1, height], [*q0, height]], CLS, coping, UP))
        parts.append(polygon([[*o0, zc], [*o1, zc], [*o1, height], [*o0, height]], CLS, coping, out))
        parts.append(polygon([[*p0, zc], [*p1, zc], [*o1, zc], [*o0, zc]], CLS, coping, -UP))
    lo, hi = inner.min(0), inner.max(0)
    for size in ([rng.uniform(2.2, 3.2), rng.uniform(2.5, 3.5), rng.uniform(2.3, 2.8)],
                 [rng.uniform(1.0, 2.0), rng.uniform(0.8, 1.4), rng.uniform(0.8, 1.3)]):
        half = np.array(size[:2]) / 2 + 0.3
        for _ in range(8):
            c = rng.uniform(lo + half, hi - half) if np.all(hi - lo > 2 * half) else None
            if c is None:
                break
            corners = c + half * np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]])
            if _inside(inner, corners).all() and not _inside(corners, inner).any():
                parts.append(box(tuple(size), CLS, "facade_concrete", (c[0], c[1], zr + size[2] / 2), bottom=False))
                break
    return merge(parts)


def _quad(points, material, hint) -> Mesh:
    """A polygon from points with repeated corners removed (a hip apex makes quads into triangles)."""
    pts = []
    for p in np.asarray(points, float):
        if not pts or np.linalg.norm(p - pts[-1]) > 1e-9:
            pts.append(p)
    if np.linalg.norm(pts[0] - pts[-1]) < 1e-9:
        pts.pop()
    return polygon(np.array(pts), CLS, material, hint)


def pitched_roof(rng: np.random.Generator, rect: tuple[float, float, float, float], height: float,
                 kind: str, facade_mat: str) -> Mesh:
    """A gable or hip roof over the rectangle ``rect`` = (cx, cy, hx, hy), eaves at ``height``.

    The ridge runs along the long side. Overhang 0.3-0.5 m, pitch 28-42 degrees, an optional
    brick chimney.
    """
    cx, cy, hx, hy = rect
    a, b, yaw = (hx, hy, 0.0) if hx >= hy else (hy, hx, np.pi / 2)
    tan = float(np.tan(np.radians(rng.uniform(28, 42))))
    o = float(rng.uniform(0.3, 0.5))
    t = 0.15
    zr = height + b * tan
    ze = height - o * tan
    A, B = a + o, b + o
    r = 0.0 if kind == "hip" and a - b < 0.05 else (a - b if kind == "hip" else A)
    if kind == "gable":
        A = a + float(rng.uniform(0.15, 0.3))
        r = A
    parts = []
    for dz, mat, sgn in ((t, "roof", 1.0), (0.0, "roof", -1.0)):
        s, n = [-A, -B, ze + dz], [-A, B, ze + dz]
        se, ne = [A, -B, ze + dz], [A, B, ze + dz]
        rw, re = [-r, 0, zr + dz], [r, 0, zr + dz]
        hint = lambda v, sgn=sgn: np.array(v) if sgn > 0 else -UP  # noqa: E731 - undersides face down
        parts.append(_quad([s, se, re, rw], mat, hint([0, -1, 1])))
        parts.append(_quad([ne, n, rw, re], mat, hint([0, 1, 1])))
        if kind == "hip":
            parts.append(_quad([se, ne, re], mat, hint([1, 0, 1])))
            parts.append(_quad([n, s, rw], mat, hint([-1, 0, 1])))
    # fascia boards (and bargeboards on the gable ends)
    for y, hint in ((-B, [0, -1, 0]), (B, [0, 1, 0])):
        parts.append(_quad([[-A, y, ze], [A, y, ze], [A, y, ze + t], [-A, y, ze + t]], "window_frame", hint))
    for x in (-A, A):
        hint = [np.sign(x), 0, 0]
        if kind == "hip":
            parts.append(_quad([[x, -B, ze], [x, B, ze], [x, B, ze + t], [x, -B, ze + t]], "window_frame", hint))
        else:
            for y in (-B, B):
                parts.append(_quad([[x, y, ze], [x, 0, zr], [x, 0, zr + t], [x, y, ze + t]], "window_frame", hint))
            parts.append(_quad([[np.sign(x) * a, -b, height], [np.sign(x) * a, b, height], [np.sign(x) * a, 0, zr]],
                               facade_mat, hint))
    if rng.random() < 0.6:
        xc = float(rng.uniform(-0.6, 0.6) * max(a - 0.5, 0.0))
        yc = float(rng.uniform(-0.5, 0.5) * b)
        dist = max(abs(yc), abs(xc) - r) if kind == "hip" else abs(yc)
        top = max(zr + 0.3, zr + t - dist * tan + 0.9)
        parts.append(box((0.5, 0.6, top - height), CLS, "facade_brick", (xc, yc, (top + height) / 2), bottom=False))
    return merge(parts).transformed(pose(cx, cy, 0.0, yaw))
