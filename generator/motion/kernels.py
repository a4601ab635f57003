"""The scene flow's per-point loops, compiled (numba).

Written as numpy expressions (a (3, 4) matrix gathered per point, the points stacked out of their
records, the panorama filled with ``np.minimum.at``) the scene flow of a 130k-point sweep took
~30 ms of CPU, half a sweep's cast. Here each step is one pass over the points, and the arithmetic
that can run in SIMD lanes does: a sweep's coordinates are first gathered out of its 40-byte point
records into three contiguous arrays (:func:`gather`, one pass over the records' memory), so
:func:`directions` (azimuth cell, elevation bin and range of every point, branch-free) vectorises
-- about 7x faster than on the strided fields. The passes that look things up by index
(:func:`scatter_min` into the panorama, :func:`apply_flows` with its per-column transform,
:func:`judge` against the panorama) stay scalar. Every kernel releases the GIL and the per-point
ones work on whatever slice they are given, so :class:`generator.motion.scene_flow.SceneFlow` splits
them over two threads. Azimuths use :func:`_atan2`, a polynomial (max error 1e-5 rad, ~1/300 of an azimuth
cell); the panorama and the flags use the same one, so cells agree.
"""

from __future__ import annotations

import numpy as np
from numba import njit

_PI = np.float32(np.pi)
_HALF_PI = np.float32(np.pi / 2)
#: Elevation bins beyond this many are clipped (an int32 conversion must not overflow).
_BIG = np.float32(1e9)


@njit(nogil=True, cache=True, boundscheck=False, inline="always")
def _atan2(y, x):  # pragma: no cover - compiled
    """float32 ``atan2(y, x)`` in [-pi, pi], max error ~1e-5 rad (7th-order minimax polynomial of atan)."""
    ax, ay = abs(x), abs(y)
    mx = ax if ax > ay else ay
    mn = ay if ax > ay else ax
    a = mn / mx if mx > 0 else np.float32(0.0)
    s = a * a
    r = a * (np.float32(0.99997726) + s * (np.float32(-0.33262347) + s * (np.float32(0.19354346) + s * (
        np.float32(-0.11643287) + s * (np.float32(0.05265332) + s * np.float32(-0.01172120))))))
    if ay > ax:
        r = _HALF_PI - r
    if x < 0:
        r = _PI - r
    return -r if y < 0 else r


@njit(nogil=True, cache=True, boundscheck=False)
def relative_poses(P, Q, M, E):  # pragma: no cover - compiled
    """``E[k] = (inv(Q[k] M) @ P[k] M)[:3]``: the LiDAR frame at ``t_p`` into the one at ``t_p + dt``.

    ``P``, ``Q`` (k, 4, 4) rigid ego poses at the two instants, ``M`` (4, 4) the LiDAR mount
    (``T_ego_lidar``); ``E`` (k, 3, 4) float64.
    """
    A = np.empty((4, 4))
    B = np.empty((4, 4))
    for k in range(P.shape[0]):
        for i in range(4):
            for j in range(4):
                A[i, j] = P[k, i, 0] * M[0, j] + P[k, i, 1] * M[1, j] + P[k, i, 2] * M[2, j] + P[k, i, 3] * M[3, j]
                B[i, j] = Q[k, i, 0] * M[0, j] + Q[k, i, 1] * M[1, j] + Q[k, i, 2] * M[2, j] + Q[k, i, 3] * M[3, j]
        for i in range(3):
            for j in range(3):
                E[k, i, j] = B[0, i] * A[0, j] + B[1, i] * A[1, j] + B[2, i] * A[2, j]
            d0, d1, d2 = A[0, 3] - B[0, 3], A[1, 3] - B[1, 3], A[2, 3] - B[2, 3]
            E[k, i, 3] = B[0, i] * d0 + B[1, i] * d1 + B[2, i] * d2


@njit(nogil=True, cache=True, boundscheck=False)
def gather(x, y, z, instance, lookup, out, on_actor):  # pragma: no cover - compiled
    """Coordinates into ``out`` (3, n) float32 and ``on_actor`` (n,) uint8 (1 where ``lookup[instance] >= 0``;
    ids past the table have no actor), one pass over the records."""
    size = lookup.shape[0]
    for i in range(x.shape[0]):
        out[0, i], out[1, i], out[2, i] = x[i], y[i], z[i]
        inst = np.int64(instance[i])
        on_actor[i] = 1 if (inst < size and lookup[inst] >= 0) else 0


@njit(nogil=True, cache=True, boundscheck=False)
def directions(xyz, z0, t_lo, t_scale, steps, k_out, c_out, r_out):  # pragma: no cover - compiled
    """Points ``xyz`` (3, n) float32: elevation bin, azimuth cell and range from the beams' mean emission
    point (``z0`` above the origin), branch-free so it vectorises (a loop over ``range(start, stop)``
    would not: callers pass slices).

    ``k_out`` (n,) int32: ``(dz / rho - t_lo) * t_scale`` (not clipped to the table: out of the view's
    tangents when < 0 or beyond it); ``c_out`` (n,) int32 in ``0 .. steps - 1``; ``r_out`` (n,) float32 metres.
    """
    a_scale = np.float32(steps / (2.0 * np.pi))
    tl, ts, zf = np.float32(t_lo), np.float32(t_scale), np.float32(z0)
    tiny = np.float32(1e-20)
    last = np.int32(steps - 1)
    for i in range(xyz.shape[1]):
        dx, dy, dz = xyz[0, i], xyz[1, i], xyz[2, i] - zf
        rho2 = dx * dx + dy * dy
        t = dz / max(np.sqrt(rho2), tiny)
        k_out[i] = np.int32(max(min((t - tl) * ts, _BIG), -_BIG))
        c = np.int32((_atan2(dy, dx) + _PI) * a_scale)
        c_out[i] = min(max(c, np.int32(0)), last)
        r_out[i] = np.sqrt(rho2 + dz * dz)


@njit(nogil=True, cache=True, boundscheck=False)
def scatter_min(k, c, r, lut_nearest, pan):  # pragma: no cover - compiled
    """The range panorama ``pan`` (steps, rows) float32 (preset to inf): per direction cell the nearest range;
    a point's row is the beam nearest its elevation bin (``lut_nearest``)."""
    n_k = lut_nearest.shape[0]
    for i in range(k.shape[0]):
        kk = k[i]
        j = lut_nearest[0 if kk < 0 else (n_k - 1 if kk >= n_k else kk)]
        if r[i] < pan[c[i], j]:
            pan[c[i], j] = r[i]


@njit(nogil=True, cache=True, boundscheck=False)
def apply_flows(xyz, col, which, E, L, obj, moved):  # pragma: no cover - compiled
    """Each point's object flow and where the next sweep sees it.

    Parameters
    ----------
    xyz : (3, n) float32
        Points, LiDAR frame at their firing instants (:func:`gather`).
    col : (n,) integer
        Firing column of each point.
    which : (n,) int64
        Row of ``L`` of each point; 0 for the static town (no displacement).
    E : (steps, 3, 4) float64
        Per column: LiDAR frame at ``t_p`` -> LiDAR frame at ``t_p + dt`` (:func:`relative_poses`).
    L : (R, 3, 4) float64
        Per (actor, column): the actor's displacement ``t_p -> t_p + dt`` in the LiDAR frame at
        ``t_p``; row 0 unused.
    obj : (n, 3) float32
        Written: ``L x - x`` (0 on the static town).
    moved : (3, n) float32
        Written: ``E (L x)``.
    """
    for p in range(which.shape[0]):
        a, b, c = np.float64(xyz[0, p]), np.float64(xyz[1, p]), np.float64(xyz[2, p])
        w = which[p]
        if w == 0:
            q0, q1, q2 = a, b, c
        else:
            q0 = L[w, 0, 0] * a + L[w, 0, 1] * b + L[w, 0, 2] * c + L[w, 0, 3]
            q1 = L[w, 1, 0] * a + L[w, 1, 1] * b + L[w, 1, 2] * c + L[w, 1, 3]
            q2 = L[w, 2, 0] * a + L[w, 2, 1] * b + L[w, 2, 2] * c + L[w, 2, 3]
        k = np.int64(col[p])
        moved[0, p] = E[k, 0, 0] * q0 + E[k, 0, 1] * q1 + E[k, 0, 2] * q2 + E[k, 0, 3]
        moved[1, p] = E[k, 1, 0] * q0 + E[k, 1, 1] * q1 + E[k, 1, 2] * q2 + E[k, 1, 3]
        moved[2, p] = E[k, 2, 0] * q0 + E[k, 2, 1] * q1 + E[k, 2, 2] * q2 + E[k, 2, 3]
        obj[p, 0], obj[p, 1], obj[p, 2] = q0 - a, q1 - b, q2 - c


@njit(nogil=True, cache=True, boundscheck=False)
def judge(k, c, r, pan, lut_below, rmin, rmax, out):  # pragma: no cover - compiled
    """Moved points (:func:`directions`): 0 seen, 1 hidden, 2 gone
    (:func:`generator.motion.scene_flow.next_sweep_flags`) against the next sweep's panorama ``pan``.

    ``lut_below`` (K,): the highest beam row at or below each elevation bin (-1: below the lowest
    beam); a bin outside ``0 .. K - 1`` is out of the view.
    """
    n_rows = pan.shape[1]
    n_k = lut_below.shape[0]
    rmin32, rmax32 = np.float32(rmin), np.float32(rmax)
    for p in range(k.shape[0]):
        kk, rr = k[p], r[p]
        if kk < 0 or kk >= n_k or rr < rmin32 or rr > rmax32:
            out[p] = 2
            continue
        below = lut_below[kk]
        lo = below if below > 0 else 0
        hi = below + 1 if below + 1 < n_rows else n_rows - 1
        tol = np.float32(0.03) * rr
        limit = rr - (tol if tol > np.float32(0.25) else np.float32(0.25))
        cc = c[p]
        out[p] = 1 if (pan[cc, lo] < limit and pan[cc, hi] < limit) else 0
