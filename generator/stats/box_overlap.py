"""Overlaps of KITTI boxes as KITTI's object devkit defines them (``evaluate_object.cpp``).

* 2D: intersection over union of image boxes ``(x1, y1, x2, y2)``, areas ``(x2 - x1) (y2 - y1)``
  (no +1); with ``criterion`` 0 the intersection over the first box's area (DontCare regions).
* bird's eye view: intersection over union of the ground rectangles in the camera's x-z plane,
  centre ``(x, z)``, length ``l`` along the heading, width ``w``, turned by ``rotation_y``;
* 3D: that ground intersection times the overlap of the vertical extents ``[y - h, y]`` (camera y
  points down, ``y`` is the bottom face), over the union of the volumes.

The rectangles are intersected exactly (convex polygon clipping, all pairs at once in numpy).
"""

from __future__ import annotations

import numpy as np


def image_iou(a: np.ndarray, b: np.ndarray, criterion: int = -1) -> np.ndarray:
    """(n, m) overlaps of image boxes ``a`` (n, 4) and ``b`` (m, 4): IoU, or over ``a``'s area (criterion 0)."""
    a, b = np.asarray(a, np.float64).reshape(-1, 4), np.asarray(b, np.float64).reshape(-1, 4)
    w = np.minimum(a[:, None, 2], b[None, :, 2]) - np.maximum(a[:, None, 0], b[None, :, 0])
    h = np.minimum(a[:, None, 3], b[None, :, 3]) - np.maximum(a[:, None, 1], b[None, :, 1])
    inter = np.where((w > 0) & (h > 0), w * h, 0.0)
    area_a = (a[:, 2] - a[:, 0]) * (a[:, 3] - a[:, 1])
    area_b = (b[:, 2] - b[:, 0]) * (b[:, 3] - b[:, 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        if criterion == 0:
            out = inter / area_a[:, None]
        else:
            out = inter / (area_a[:, None] + area_b[None, :] - inter)
    return np.where(inter > 0, out, 0.0)


def ground_rectangles(xz: np.ndarray, lw: np.ndarray, ry: np.ndarray) -> np.ndarray:
    """(n, 4, 2) corners in the x-z plane of rectangles centred at ``xz`` (n, 2), sizes ``lw`` (n, 2) (length
    along the heading, width), turned by ``ry`` (n,) as the devkit turns them (x' = c x + s z, z' = -s x + c z)."""
    c, s = np.cos(ry)[:, None], np.sin(ry)[:, None]
    hl, hw = lw[:, :1] / 2, lw[:, 1:2] / 2
    lx = np.hstack([hl, hl, -hl, -hl])
    lz = np.hstack([hw, -hw, -hw, hw])
    return np.stack([c * lx + s * lz + xz[:, :1], -s * lx + c * lz + xz[:, 1:2]], -1)


def _area(poly: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Shoelace area of (P, M, 2) polygons with ``n`` (P,) valid leading vertices."""
    m = poly.shape[1]
    idx = np.arange(m)[None]
    nxt = np.where(idx + 1 < n[:, None], idx + 1, 0)
    q = np.take_along_axis(poly, nxt[..., None], 1)
    cross = poly[..., 0] * q[..., 1] - poly[..., 1] * q[..., 0]
    return 0.5 * np.abs(np.where(idx < n[:, None], cross, 0.0).sum(1))


def convex_intersection_area(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(P,) areas of the intersections of convex quadrilaterals ``a[k]`` and ``b[k]`` ((P, 4, 2) each).

    Sutherland-Hodgman: ``a`` clipped by the four edges of ``b``, every pair at once.
    """
    poly = np.asarray(a, np.float64).copy()
    b = np.asarray(b, np.float64)
    n = np.full(len(poly), 4)
    e0, e1 = b, np.roll(b, -1, axis=1)
    orient = np.sign((e0[:, :, 0] * e1[:, :, 1] - e0[:, :, 1] * e1[:, :, 0]).sum(1))[:, None]   # b's winding
    for k in range(4):
        pa, d = e0[:, k][:, None], (e1[:, k] - e0[:, k])[:, None]
        m = poly.shape[1]
        idx = np.arange(m)[None]
        valid = idx < n[:, None]
        nxt = np.where(idx + 1 < n[:, None], idx + 1, 0)
        q = np.take_along_axis(poly, nxt[..., None], 1)
        sp = orient * (d[..., 0] * (poly[..., 1] - pa[..., 1]) - d[..., 1] * (poly[..., 0] - pa[..., 0]))
        sq = orient * (d[..., 0] * (q[..., 1] - pa[..., 1]) - d[..., 1] * (q[..., 0] - pa[..., 0]))
        inp, inq = sp >= 0, sq >= 0
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.where(inp != inq, sp / (sp - sq), 0.0)
        cut = poly + t[..., None] * (q - poly)
        out = np.stack([poly, cut], 2).reshape(len(poly), 2 * m, 2)
        keep = np.stack([inp & valid, (inp != inq) & valid], 2).reshape(len(poly), 2 * m)
        order = np.argsort(~keep, axis=1, kind="stable")
        poly = np.take_along_axis(out, order[..., None], 1)[:, :8]
        n = np.minimum(keep.sum(1), 8)
    return np.where(n >= 3, _area(poly, n), 0.0)


def _pairs(d_rect: np.ndarray, g_rect: np.ndarray) -> np.ndarray:
    """(n, m) intersection areas of every pair of ground rectangles (far pairs skipped)."""
    n, m = len(d_rect), len(g_rect)
    out = np.zeros((n, m))
    if not n or not m:
        return out
    cd, cg = d_rect.mean(1), g_rect.mean(1)
    rd = np.linalg.norm(d_rect - cd[:, None], axis=2).max(1)
    rg = np.linalg.norm(g_rect - cg[:, None], axis=2).max(1)
    near = np.linalg.norm(cd[:, None] - cg[None], axis=2) < rd[:, None] + rg[None]
    i, j = np.nonzero(near)
    if len(i):
        out[i, j] = convex_intersection_area(d_rect[i], g_rect[j])
    return out


def bev_iou(d: dict, g: dict) -> np.ndarray:
    """(n, m) bird's-eye-view IoU of detections ``d`` and ground truth ``g`` (dicts of ``location`` (k, 3),
    ``dimensions`` (k, 3) h w l, ``rotation_y`` (k,))."""
    dr, gr = _rects(d), _rects(g)
    inter = _pairs(dr, gr)
    ad = d["dimensions"][:, 2] * d["dimensions"][:, 1]
    ag = g["dimensions"][:, 2] * g["dimensions"][:, 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(inter > 0, inter / (ad[:, None] + ag[None] - inter), 0.0)


def box3d_iou(d: dict, g: dict) -> np.ndarray:
    """(n, m) 3D IoU of detections ``d`` and ground truth ``g`` (as :func:`bev_iou`)."""
    inter = _pairs(_rects(d), _rects(g))
    yd, hd = d["location"][:, 1], d["dimensions"][:, 0]
    yg, hg = g["location"][:, 1], g["dimensions"][:, 0]
    dh = np.maximum(0.0, np.minimum(yd[:, None], yg[None]) - np.maximum((yd - hd)[:, None], (yg - hg)[None]))
    vol = inter * dh
    vd = np.prod(d["dimensions"], 1)
    vg = np.prod(g["dimensions"], 1)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(vol > 0, vol / (vd[:, None] + vg[None] - vol), 0.0)


def _rects(b: dict) -> np.ndarray:
    loc = np.asarray(b["location"], np.float64).reshape(-1, 3)
    dim = np.asarray(b["dimensions"], np.float64).reshape(-1, 3)
    return ground_rectangles(loc[:, [0, 2]], dim[:, [2, 1]], np.asarray(b["rotation_y"], np.float64).reshape(-1))
