"""The occupancy's separating-axis test, compiled (numba, GIL released).

The placer's occupancy (``Occupancy.hits`` in :mod:`generator.layout.placement`) asks ~1500 times
per town whether a few collision boxes overlap any of the accepted boxes near them. As numpy
expressions (:func:`generator.geometry.boxes.boxes_overlap`) each question is ~60 short array passes
on arrays of a few dozen pairs; here it is one loop that stops at the first overlap.

The arithmetic is the float64 arithmetic of ``boxes_overlap``, in the same order and without fused
multiply-adds (numba's default, no ``fastmath``), so every answer is the same: per axis ``n``
of the four box axes, ``|n . d| < hx_a |n . ax_a| + hy_a |n . ay_a| + hx_b |n . ax_b| +
hy_b |n . ay_b|`` with ``n . v = n0 v0 + n1 v1``, and the z intervals overlap strictly. The
cosines and sines of the yaws are numpy's (computed by the caller), not libm's.
"""

from __future__ import annotations

from numba import njit


@njit(inline="always")
def _separated(nx, ny, ax0, ax1, ay0, ay1, bx0, bx1, by0, by1, ahx, ahy, bhx, bhy, dx, dy):  # pragma: no cover
    ra = ahx * abs(nx * ax0 + ny * ax1) + ahy * abs(nx * ay0 + ny * ay1)
    rb = bhx * abs(nx * bx0 + ny * bx1) + bhy * abs(nx * by0 + ny * by1)
    return not (abs(nx * dx + ny * dy) < ra + rb)


@njit(nogil=True, cache=True, boundscheck=False)
def any_overlap(a, a_cos, a_sin, b, b_cos, b_sin):  # pragma: no cover - compiled
    """Does any box of ``a`` overlap any box of ``b``?

    Parameters
    ----------
    a : (k, 7) float64
        Boxes ``(cx, cy, hx, hy, yaw, z0, z1)``, world frame, metres and radians.
    a_cos, a_sin : (k,) float64
        ``numpy.cos`` and ``numpy.sin`` of ``a[:, 4]``.
    b, b_cos, b_sin
        The same for the other set, (m, 7) and (m,).

    Returns
    -------
    bool
        ``boxes_overlap(a, b).any()``.
    """
    for i in range(a.shape[0]):
        ca, sa = a_cos[i], a_sin[i]
        ahx, ahy = a[i, 2], a[i, 3]
        for j in range(b.shape[0]):
            if not (a[i, 5] < b[j, 6] and b[j, 5] < a[i, 6]):
                continue
            cb, sb = b_cos[j], b_sin[j]
            bhx, bhy = b[j, 2], b[j, 3]
            dx, dy = b[j, 0] - a[i, 0], b[j, 1] - a[i, 1]
            # box axes: x = (c, s), y = (-s, c); the four candidate separating axes in boxes_overlap's order
            if _separated(ca, sa, ca, sa, -sa, ca, cb, sb, -sb, cb, ahx, ahy, bhx, bhy, dx, dy):
                continue
            if _separated(-sa, ca, ca, sa, -sa, ca, cb, sb, -sb, cb, ahx, ahy, bhx, bhy, dx, dy):
                continue
            if _separated(cb, sb, ca, sa, -sa, ca, cb, sb, -sb, cb, ahx, ahy, bhx, bhy, dx, dy):
                continue
            if _separated(-sb, cb, ca, sa, -sa, ca, cb, sb, -sb, cb, ahx, ahy, bhx, bhy, dx, dy):
                continue
            return True
    return False
