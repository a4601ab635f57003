"""The amodal footprint of an object in an image: its own triangles, projected and rasterised in numpy.

The label pass samples each pixel at its centre (or votes over ``k x k`` sub-samples,
:mod:`generator.labels.supersample`); the footprint here is sampled the same way, so the pixels of
an unoccluded object in the instance pass are the pixels of its footprint.

Pixel convention (:mod:`generator.world.rig`): ``u = fx x / z + cx``, ``v = fy y / z + cy`` in an
optical camera frame (x right, y down, z forward); pixel ``(row i, col j)`` covers
``[j, j + 1) x [i, i + 1)`` and is sampled at its centre ``(j + 0.5, i + 0.5)``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: Triangles are clipped at this depth in front of the camera, metres (what lies closer is not imaged).
NEAR_M = 0.05


def clip_near(tri: np.ndarray, near: float = NEAR_M) -> np.ndarray:
    """Clip camera-frame triangles against the plane ``z = near``.

    Parameters
    ----------
    tri : (T, 3, 3) float64
        Triangles (vertex rows), camera frame, metres.

    Returns
    -------
    (T', 3, 3) float64
        The parts with ``z >= near``: a triangle with one vertex behind becomes two, with two behind one.
    """
    tri = np.asarray(tri, np.float64)
    front = tri[..., 2] >= near
    n = front.sum(1)
    out = [tri[n == 3]]
    for k in (1, 2):
        t = tri[n == k]
        if not len(t):
            continue
        f = front[n == k]
        # roll each triangle so the lone vertex (the one in front for k=1, behind for k=2) comes first
        lone = np.argmax(f if k == 1 else ~f, axis=1)
        idx = (lone[:, None] + np.arange(3)[None]) % 3
        t = np.take_along_axis(t, idx[..., None], axis=1)
        a, b, c = t[:, 0], t[:, 1], t[:, 2]

        def cut(p, q):  # the point of segment p-q at z = near
            s = ((near - p[:, 2]) / (q[:, 2] - p[:, 2]))[:, None]
            return p + s * (q - p)

        ab, ac = cut(a, b), cut(a, c)
        if k == 1:
            out.append(np.stack([a, ab, ac], 1))
        else:
            out.append(np.stack([ab, b, c], 1))
            out.append(np.stack([ab, c, ac], 1))
    return np.concatenate(out) if out else np.zeros((0, 3, 3))


def project(tri_cam: np.ndarray, K: np.ndarray) -> np.ndarray:
    """(T, 3, 2) float64 pixel coordinates of camera-frame triangles (all in front of the camera)."""
    p = tri_cam @ np.asarray(K, np.float64).T
    return p[..., :2] / p[..., 2:3]


@njit(cache=True, nogil=True)
def _fill(g: np.ndarray, mask: np.ndarray) -> None:
    """Set the samples of ``mask`` whose centres lie in a triangle of ``g`` ((T, 3, 2), sample index space)."""
    height, width = mask.shape
    for t in range(g.shape[0]):
        ax, ay, bx, by, cx, cy = g[t, 0, 0], g[t, 0, 1], g[t, 1, 0], g[t, 1, 1], g[t, 2, 0], g[t, 2, 1]
        area = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
        if abs(area) <= 1e-12:
            continue
        sgn = 1.0 if area > 0 else -1.0
        x0 = max(int(np.ceil(min(ax, bx, cx))), 0)
        x1 = min(int(np.floor(max(ax, bx, cx))), width - 1)
        y0 = max(int(np.ceil(min(ay, by, cy))), 0)
        y1 = min(int(np.floor(max(ay, by, cy))), height - 1)
        for y in range(y0, y1 + 1):
            for x in range(x0, x1 + 1):
                if (sgn * ((bx - ax) * (y - ay) - (by - ay) * (x - ax)) >= 0
                        and sgn * ((cx - bx) * (y - by) - (cy - by) * (x - bx)) >= 0
                        and sgn * ((ax - cx) * (y - cy) - (ay - cy) * (x - cx)) >= 0):
                    mask[y, x] = True


def rasterise(uv: np.ndarray, width: int, height: int, origin=(0.0, 0.0), step: float = 1.0) -> np.ndarray:
    """Which sample points lie in at least one triangle (edges included).

    Parameters
    ----------
    uv : (T, 3, 2) float64
        Triangles in pixel coordinates.
    width, height : int
        Grid size in samples.
    origin : (2,) float
        Pixel coordinates of the corner of sample ``(0, 0)``; sample ``(i, j)`` is at
        ``origin + ((j + 0.5) step, (i + 0.5) step)``.
    step : float
        Sample spacing in pixels (1: pixel centres; ``1/k``: a ``k``-times supersampled grid).

    Returns
    -------
    (height, width) bool
    """
    mask = np.zeros((height, width), np.bool_)
    if len(uv):
        g = (np.asarray(uv, np.float64) - np.asarray(origin, np.float64)) / step - 0.5   # sample index space
        _fill(np.ascontiguousarray(g), mask)
    return mask


def footprint(tri_cam: np.ndarray, K: np.ndarray, width: int, height: int,
              supersample: int = 1) -> tuple[np.ndarray, tuple[int, int]]:
    """The amodal mask of camera-frame triangles in the image, sampled as the label pass, over the window
    of the image they cover.

    ``supersample`` ``k`` > 1: a pixel is covered when more than half of its ``k x k`` sub-samples are
    (the label pass's majority vote); 1: when its centre is.

    Returns
    -------
    mask : (h, w) bool
        The window's pixels (empty when the triangles miss the image).
    origin : (int, int)
        Column and row of the window's top-left pixel in the image.
    """
    uv = project(clip_near(tri_cam), K)
    if not len(uv):
        return np.zeros((0, 0), bool), (0, 0)
    flat = uv.reshape(-1, 2)
    x0, y0 = (int(max(np.floor(v), 0)) for v in flat.min(0))
    x1, y1 = int(min(np.ceil(flat[:, 0].max()), width)), int(min(np.ceil(flat[:, 1].max()), height))
    if x1 <= x0 or y1 <= y0:
        return np.zeros((0, 0), bool), (0, 0)
    w, h = x1 - x0, y1 - y0
    k = int(supersample)
    if k <= 1:
        return rasterise(uv, w, h, origin=(x0, y0)), (x0, y0)
    sub = rasterise(uv, w * k, h * k, origin=(x0, y0), step=1.0 / k)
    return sub.reshape(h, k, w, k).sum((1, 3)) * 2 > k * k, (x0, y0)


def coverage_outside(tri_cam: np.ndarray, K: np.ndarray, width: int, height: int,
                     max_samples: int = 2_000_000, reach: float = 4.0) -> float:
    """Share of the projected area of camera-frame triangles that lies outside the image (truncation).

    The projection is sampled on one grid over its bounding box (clamped to ``reach`` image sizes
    beyond each side: a part of an object crossing the camera plane projects to infinity and counts
    as outside up to there) at the pixel grid when that fits in ``max_samples``, else coarser.
    Returns 0 when the projection lies inside the image, 1 when it lies wholly outside.
    """
    uv = project(clip_near(tri_cam), K)
    if not len(uv):
        return 1.0
    lo, hi = uv.reshape(-1, 2).min(0), uv.reshape(-1, 2).max(0)
    if lo[0] >= 0 and lo[1] >= 0 and hi[0] <= width and hi[1] <= height:
        return 0.0
    lo = np.maximum(np.floor(lo), [-reach * width, -reach * height])
    hi = np.minimum(np.ceil(hi), [(1 + reach) * width, (1 + reach) * height])
    span = np.maximum(hi - lo, 1.0)
    step = max(1.0, float(np.sqrt(span[0] * span[1] / max_samples)))
    nx, ny = int(np.ceil(span[0] / step)), int(np.ceil(span[1] / step))
    m = rasterise(uv, nx, ny, origin=lo, step=step)
    total = int(m.sum())
    if total == 0:
        return 1.0 if (hi[0] <= 0 or hi[1] <= 0 or lo[0] >= width or lo[1] >= height) else 0.0
    cx = lo[0] + (np.arange(nx) + 0.5) * step
    cy = lo[1] + (np.arange(ny) + 0.5) * step
    inside = ((cy >= 0) & (cy < height))[:, None] & ((cx >= 0) & (cx < width))[None, :]
    return float(1.0 - (m & inside).sum() / total)
