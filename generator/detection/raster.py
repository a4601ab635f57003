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

#: Triangles are clipped at this depth in front of the camera, metres (what lies closer is not imaged).
NEAR_M = 0.05
#: Candidate samples tested per chunk (bounds the memory of one rasterisation step).
CHUNK_SAMPLES = 4_000_000


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


def rasterise(uv: np.ndarray, width: int, height: int, origin=(0.0, 0.0), step: float = 1.0) -> np.ndarray:
    """Which sample points lie in at least one triangle.

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
    mask = np.zeros((height, width), bool)
    g = (np.asarray(uv, np.float64) - np.asarray(origin, np.float64)) / step - 0.5   # sample index space
    if not len(g):
        return mask
    a, b, c = g[:, 0], g[:, 1], g[:, 2]
    area = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    lo = np.maximum(np.ceil(g.min(1)), 0).astype(np.int64)
    hi = np.minimum(np.floor(g.max(1)), [width - 1, height - 1]).astype(np.int64)
    keep = (np.abs(area) > 1e-12) & (hi[:, 0] >= lo[:, 0]) & (hi[:, 1] >= lo[:, 1])
    g, area, lo, hi = g[keep], area[keep], lo[keep], hi[keep]
    nx, ny = hi[:, 0] - lo[:, 0] + 1, hi[:, 1] - lo[:, 1] + 1
    cost = nx * ny
    ends = np.cumsum(cost)
    start = 0
    while start < len(g):
        stop = int(np.searchsorted(ends, (ends[start - 1] if start else 0) + CHUNK_SAMPLES, side="right"))
        stop = max(stop, start + 1)
        sl = slice(start, stop)
        n = cost[sl]
        tri = np.repeat(np.arange(start, stop), n)
        k = np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)
        x = lo[tri, 0] + k % nx[tri]
        y = lo[tri, 1] + k // nx[tri]
        sgn = np.sign(area[tri])
        inside = np.ones(len(tri), bool)
        for e0, e1 in ((0, 1), (1, 2), (2, 0)):
            p, q = g[tri, e0], g[tri, e1]
            inside &= sgn * ((q[:, 0] - p[:, 0]) * (y - p[:, 1]) - (q[:, 1] - p[:, 1]) * (x - p[:, 0])) >= 0
        mask[y[inside], x[inside]] = True
        start = stop
    return mask


def footprint(tri_cam: np.ndarray, K: np.ndarray, width: int, height: int, supersample: int = 1) -> np.ndarray:
    """(height, width) bool amodal mask of camera-frame triangles in the image, sampled as the label pass.

    ``supersample`` ``k`` > 1: a pixel is covered when more than half of its ``k x k`` sub-samples are
    (the label pass's majority vote); 1: when its centre is.
    """
    uv = project(clip_near(tri_cam), K)
    k = int(supersample)
    if k <= 1:
        return rasterise(uv, width, height)
    sub = rasterise(uv, width * k, height * k, step=1.0 / k)
    return sub.reshape(height, k, width, k).sum((1, 3)) * 2 > k * k


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
