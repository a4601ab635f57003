"""Box geometry, in one place: upright oriented boxes, their corners, overlap and distances.

Two forms of the same thing:

* :class:`OrientedBox`, one upright box (centre, size, yaw), what a scene object or an actor carries;
* box *rows* ``(cx, cy, hx, hy, yaw, z0, z1)``: many boxes in an (n, 7) float64 array -- centre,
  half length along ``yaw``, half width, heading (radians) and the z interval -- the form placement
  (collision bands), walkers and obstacles test by the thousand.

Footprints as *quads*: (..., 4, 2) corners from :func:`corners`, counter-clockwise from the
rear right corner, for boxes swept along a path. Overlap is the separating-axis test in 2D (with
the z intervals for rows, strictly overlapping): :func:`box_pairs_overlap` / :func:`boxes_overlap`
for rows, :func:`quad_pairs_overlap` / :func:`quads_overlap` for quads; the compiled twin of
:func:`boxes_overlap` (``any`` of it, for the placer's occupancy) is
:func:`generator.geometry.overlap_kernel.any_overlap`. Frames: whichever frame the boxes are in
(world or a town's grid), metres, yaw counter-clockwise from +x.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class OrientedBox:
    """An upright oriented 3D box.

    Attributes
    ----------
    center : (3,) float64
        Box centre, world frame, metres.
    size : (3,) float64
        Length (along heading), width, height in metres.
    yaw : float
        Heading of the length axis, radians, counter-clockwise from +x.
    """

    center: tuple[float, float, float]
    size: tuple[float, float, float]
    yaw: float

    def corners_xy(self) -> np.ndarray:
        """(4, 2) float64 footprint corners, counter-clockwise."""
        return corners(np.asarray(self.center[:2])[None], np.array([self.yaw]), self.size[:2])[0]

    def contains(self, points: np.ndarray, margin: float = 0.0) -> np.ndarray:
        """(n,) bool: which (n, 3) world points lie inside the box grown by ``margin`` metres."""
        p = np.asarray(points, np.float64).reshape(-1, 3) - np.asarray(self.center)
        c, s = np.cos(self.yaw), np.sin(self.yaw)
        lx, ly = p[:, 0] * c + p[:, 1] * s, -p[:, 0] * s + p[:, 1] * c
        h = np.asarray(self.size) / 2 + margin
        return (np.abs(lx) <= h[0]) & (np.abs(ly) <= h[1]) & (np.abs(p[:, 2]) <= h[2])

    def quaternion(self) -> tuple[float, float, float, float]:
        """Rotation as a unit quaternion (x, y, z, w)."""
        return (0.0, 0.0, float(np.sin(self.yaw / 2)), float(np.cos(self.yaw / 2)))

    def row(self) -> np.ndarray:
        """(1, 7) box row ``(cx, cy, hx, hy, yaw, z0, z1)`` (the z interval is the box's height)."""
        return np.array([[self.center[0], self.center[1], self.size[0] / 2, self.size[1] / 2, self.yaw,
                          self.center[2] - self.size[2] / 2, self.center[2] + self.size[2] / 2]])


def corners(xy: np.ndarray, yaw: np.ndarray, size, pad: float = 0.0) -> np.ndarray:
    """(n, 4, 2) float64 corners of boxes of ``size`` centred on ``xy`` and turned by ``yaw``.

    Parameters
    ----------
    xy : (n, 2) float
        Box centres, metres.
    yaw : (n,) float
        Headings of the length axes, radians.
    size : (float, float)
        Length and width, metres, the same for every box.
    pad : float
        Grows every side by this much, metres.

    Returns
    -------
    (n, 4, 2) float64
        Counter-clockwise from the rear right: (-l, -w), (+l, -w), (+l, +w), (-l, +w) in the box frame.
    """
    hl, hw = size[0] / 2 + pad, size[1] / 2 + pad
    local = np.array([[-hl, -hw], [hl, -hw], [hl, hw], [-hl, hw]])
    c, s = np.cos(yaw), np.sin(yaw)
    rot = np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)   # (n, 2, 2)
    return np.asarray(xy, np.float64)[:, None, :2] + np.einsum("nij,kj->nki", rot, local)


def quad_pairs_overlap(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Do the convex quads ``a`` and ``b`` overlap (separating axes: two edge normals of each)?

    Parameters
    ----------
    a, b : (..., 4, 2) float
        Quads (rectangles, or the parallelograms a linear map makes of them), broadcast against
        each other over the leading axes.

    Returns
    -------
    (...) bool
        True where they overlap (touching counts).
    """
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    sep = np.zeros(np.broadcast_shapes(a.shape[:-2], b.shape[:-2]), bool)
    for q in (a, b):
        e = np.roll(q, -1, axis=-2) - q
        for j in range(2):
            n0, n1 = -e[..., j, 1][..., None], e[..., j, 0][..., None]     # (..., 1): the normal of edge j
            pa, pb = a[..., 0] * n0 + a[..., 1] * n1, b[..., 0] * n0 + b[..., 1] * n1
            sep |= (pa.max(-1) < pb.min(-1)) | (pb.max(-1) < pa.min(-1))
    return ~sep


def quads_overlap(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(n, m) bool: which quads of ``a`` (n, 4, 2) overlap which of ``b`` (m, 4, 2)."""
    return quad_pairs_overlap(np.asarray(a)[:, None], np.asarray(b)[None])


def box_pairs_overlap(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Do the box rows ``a`` and ``b`` overlap (2D separating axes and strictly overlapping z intervals)?

    Parameters
    ----------
    a, b : (..., 7) float
        Rows ``(cx, cy, hx, hy, yaw, z0, z1)``, broadcast against each other over the leading axes.

    Returns
    -------
    (...) bool
    """
    ok = (a[..., 5] < b[..., 6]) & (b[..., 5] < a[..., 6])
    ca, sa, cb, sb = np.cos(a[..., 4]), np.sin(a[..., 4]), np.cos(b[..., 4]), np.sin(b[..., 4])
    dx, dy = b[..., 0] - a[..., 0], b[..., 1] - a[..., 1]
    for nx, ny in ((ca, sa), (-sa, ca), (cb, sb), (-sb, cb)):      # the box axes: x = (c, s), y = (-s, c)
        ra = a[..., 2] * np.abs(nx * ca + ny * sa) + a[..., 3] * np.abs(nx * -sa + ny * ca)
        rb = b[..., 2] * np.abs(nx * cb + ny * sb) + b[..., 3] * np.abs(nx * -sb + ny * cb)
        ok &= np.abs(nx * dx + ny * dy) < ra + rb
    return ok


def boxes_overlap(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(k, m) bool: which rows of ``a`` (k, 7) overlap which of ``b`` (m, 7)."""
    return box_pairs_overlap(np.asarray(a)[:, None, :], np.asarray(b)[None, :, :])


def world_boxes(local: np.ndarray, transform: np.ndarray, pad: float = 0.0) -> np.ndarray:
    """Local (b, 6) AABBs ``(x0, y0, z0, x1, y1, z1)`` under a yaw-only ``transform`` -> (b, 7) rows,
    each side grown by ``pad`` metres in x and y."""
    yaw = float(np.arctan2(transform[1, 0], transform[0, 0]))
    c = (local[:, :3] + local[:, 3:]) / 2
    cw = c @ transform[:3, :3].T + transform[:3, 3]
    h = (local[:, 3:] - local[:, :3]) / 2
    z = transform[2, 3]
    return np.stack([cw[:, 0], cw[:, 1], h[:, 0] + pad, h[:, 1] + pad, np.full(len(c), yaw),
                     local[:, 2] + z, local[:, 5] + z], 1)


def box_of(lo: np.ndarray, hi: np.ndarray, transform: np.ndarray) -> OrientedBox:
    """OrientedBox of the local AABB ``lo``..``hi`` ((3,) metres) under a yaw-only ``transform``."""
    c = (np.asarray(lo) + hi) / 2 @ transform[:3, :3].T + transform[:3, 3]
    yaw = float(np.arctan2(transform[1, 0], transform[0, 0]))
    return OrientedBox(tuple(float(v) for v in c), tuple(float(v) for v in np.subtract(hi, lo)), yaw)


def point_box_distance(points: np.ndarray, box: OrientedBox) -> np.ndarray:
    """(n,) float64 2D distance from (n, 2) points to the footprint of ``box`` (0 inside)."""
    p = np.asarray(points, np.float64).reshape(-1, 2) - np.asarray(box.center[:2])
    c, s = np.cos(box.yaw), np.sin(box.yaw)
    lx, ly = np.abs(p[:, 0] * c + p[:, 1] * s), np.abs(-p[:, 0] * s + p[:, 1] * c)
    dx = np.maximum(lx - box.size[0] / 2, 0)
    dy = np.maximum(ly - box.size[1] / 2, 0)
    return np.hypot(dx, dy)


def point_polygon_distance(points: np.ndarray, polygon: np.ndarray) -> np.ndarray:
    """(n,) float64 2D distance from (n, 2) points to a convex (k, 2) counter-clockwise polygon (0 inside):
    the footprint a skewed town's map makes of a box."""
    p = np.asarray(points, np.float64).reshape(-1, 1, 2)
    a = np.asarray(polygon, np.float64).reshape(1, -1, 2)
    e = np.roll(a, -1, axis=1) - a
    t = np.clip(((p - a) * e).sum(-1) / np.maximum((e * e).sum(-1), 1e-18), 0.0, 1.0)
    d = np.linalg.norm(p - a - t[..., None] * e, axis=-1).min(1)
    inside = ((e[..., 0] * (p[..., 1] - a[..., 1]) - e[..., 1] * (p[..., 0] - a[..., 0])) >= 0).all(1)
    return np.where(inside, 0.0, d)
