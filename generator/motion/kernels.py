"""The scene flow's per-point loops, compiled (numba): two passes over a sweep's point records.

Written as numpy expressions (a (3, 4) matrix gathered per point, the points stacked out of their
records, the panorama filled with ``np.minimum.at``) the scene flow of a 130k-point sweep took
~30 ms of CPU, half a sweep's cast. Here a sweep is read twice, straight from its records' fields
(strided views, no copies): :func:`prepare` once, when the sweep arrives (its range panorama for
the sweep before it, stored (azimuth cell, beam) so one column's beams are adjacent, and which of
its points lie on actors), and :func:`flow_flags` once, when
its own flow is due (the flow, the point carried to the next sweep and that sweep's verdict on
it, in one go). Azimuths use :func:`_atan2`, a polynomial (max error 1e-5 rad, ~1/300 of an
azimuth cell) that LLVM vectorises; the panorama and the flags use the same one, so cells agree.
"""

from __future__ import annotations

import numpy as np
from numba import njit

_PI = np.float32(np.pi)
_HALF_PI = np.float32(np.pi / 2)


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


@njit(nogil=True, cache=True, boundscheck=False, inline="always")
def _cell(dx, dy, dz, t_lo, t_scale, n_k, a_scale, steps):  # pragma: no cover - compiled
    """(tangent-of-elevation bin, azimuth cell, horizontal distance) of a direction, float32."""
    rho = np.sqrt(dx * dx + dy * dy)
    k = np.int64((dz / rho - t_lo) * t_scale)
    k = 0 if k < 0 else (n_k - 1 if k >= n_k else k)
    c = np.int64((_atan2(dy, dx) + _PI) * a_scale)
    c = steps - 1 if c >= steps else (0 if c < 0 else c)
    return k, c, rho


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
def prepare(x, y, z, instance, lookup, z0, lut_nearest, t_lo, t_scale, pan, on_actor):  # pragma: no cover
    """One pass over a sweep: its range panorama and which of its points lie on actors.

    Parameters
    ----------
    x, y, z : (m,) float32
        Points, LiDAR frame at their firing instants (any strides).
    instance : (m,) integer
        Instance ids.
    lookup : (I,) int64
        Instance id -> actor index, -1 for none (ids past the table: none).
    z0 : float
        Height of the beams' mean emission point above the sensor origin, metres.
    lut_nearest : (K,) int64
        Beam row nearest to each tangent-of-elevation bin ``t_lo + k / t_scale``.
    pan : (steps, rows) float32
        Preset to inf; written: the nearest range in each direction cell; (0, 0): skipped.
    on_actor : (m,) uint8
        Written: 1 on an actor's point.
    """
    n_k, size = lut_nearest.shape[0], lookup.shape[0]
    steps = pan.shape[0]
    want = pan.shape[1] > 0
    a_scale = np.float32(steps / (2.0 * np.pi)) if want else np.float32(0.0)
    tl, ts, zf = np.float32(t_lo), np.float32(t_scale), np.float32(z0)
    for i in range(x.shape[0]):
        inst = np.int64(instance[i])
        on_actor[i] = 1 if (inst < size and lookup[inst] >= 0) else 0
        if not want:
            continue
        dx, dy, dz = x[i], y[i], z[i] - zf
        if dx == 0 and dy == 0:
            continue
        k, c, rho = _cell(dx, dy, dz, tl, ts, n_k, a_scale, steps)
        j = lut_nearest[k]
        r = np.sqrt(rho * rho + dz * dz)
        if r < pan[c, j]:
            pan[c, j] = r


@njit(nogil=True, cache=True, boundscheck=False)
def flow_flags(x, y, z, col, which, E, L, pan, lut_below, z0, t_lo, t_scale, top, bottom, rmin, rmax,
               obj, flag, moved):  # pragma: no cover - compiled
    """One pass over a sweep: each point's object flow, where the next sweep sees it, and that sweep's verdict.

    Parameters
    ----------
    x, y, z : (n,) float32
        Points, LiDAR frame at their firing instants (any strides).
    col : (n,) integer
        Firing column of each point.
    which : (n,) int64
        Row of ``L`` of each point; 0 for the static town (no displacement).
    E : (steps, 3, 4) float64
        Per column: LiDAR frame at ``t_p`` -> LiDAR frame at ``t_p + dt`` (:func:`relative_poses`).
    L : (R, 3, 4) float64
        Per (actor, column): the actor's displacement ``t_p -> t_p + dt`` in the LiDAR frame at
        ``t_p``; row 0 unused.
    pan : (steps, rows) float32
        The next sweep's panorama (:func:`prepare`); (0, 0): no flags.
    lut_below : (K,) int64
        Highest beam row at or below each tangent bin (-1: below the lowest beam).
    z0, t_lo, t_scale
        As for :func:`prepare`.
    top, bottom : float
        Tangents of the view's upper and lower edges.
    rmin, rmax : float
        Sensor range, metres.
    obj : (n, 3) float32
        Written: ``L x - x`` (0 on the static town).
    flag : (n,) uint8
        Written (with a panorama): 0 seen, 1 hidden, 2 gone
        (:func:`generator.motion.scene_flow.next_sweep_flags`).
    moved : (n, 3) or (0, 3) float32
        Written if not empty: ``E (L x)``.
    """
    steps, n_rows = pan.shape
    want_flags, want_moved = n_rows > 0, moved.shape[0] > 0
    n_k = lut_below.shape[0]
    a_scale = np.float32(steps / (2.0 * np.pi)) if want_flags else np.float32(0.0)
    tl, ts, zf = np.float32(t_lo), np.float32(t_scale), np.float32(z0)
    top32, bottom32, rmin32, rmax32 = np.float32(top), np.float32(bottom), np.float32(rmin), np.float32(rmax)
    for p in range(x.shape[0]):
        a, b, c = np.float64(x[p]), np.float64(y[p]), np.float64(z[p])
        w = which[p]
        if w == 0:
            q0, q1, q2 = a, b, c
        else:
            q0 = L[w, 0, 0] * a + L[w, 0, 1] * b + L[w, 0, 2] * c + L[w, 0, 3]
            q1 = L[w, 1, 0] * a + L[w, 1, 1] * b + L[w, 1, 2] * c + L[w, 1, 3]
            q2 = L[w, 2, 0] * a + L[w, 2, 1] * b + L[w, 2, 2] * c + L[w, 2, 3]
        k = np.int64(col[p])
        m0 = np.float32(E[k, 0, 0] * q0 + E[k, 0, 1] * q1 + E[k, 0, 2] * q2 + E[k, 0, 3])
        m1 = np.float32(E[k, 1, 0] * q0 + E[k, 1, 1] * q1 + E[k, 1, 2] * q2 + E[k, 1, 3])
        m2 = np.float32(E[k, 2, 0] * q0 + E[k, 2, 1] * q1 + E[k, 2, 2] * q2 + E[k, 2, 3])
        obj[p, 0], obj[p, 1], obj[p, 2] = q0 - a, q1 - b, q2 - c
        if want_moved:
            moved[p, 0], moved[p, 1], moved[p, 2] = m0, m1, m2
        if not want_flags:
            continue
        dz = m2 - zf
        if m0 == 0 and m1 == 0:
            flag[p] = 2
            continue
        kk, cc, rho = _cell(m0, m1, dz, tl, ts, n_k, a_scale, steps)
        r = np.sqrt(rho * rho + dz * dz)
        t = dz / rho
        if r < rmin32 or r > rmax32 or t > top32 or t < bottom32:
            flag[p] = 2
            continue
        below = lut_below[kk]
        lo = below if below > 0 else 0
        hi = below + 1 if below + 1 < n_rows else n_rows - 1
        tol = np.float32(0.03) * r
        limit = r - (tol if tol > np.float32(0.25) else np.float32(0.25))
        flag[p] = 1 if (pan[cc, lo] < limit and pan[cc, hi] < limit) else 0
