"""The scanner's two per-ray loops, compiled (numba, GIL released).

Beyond the Embree cast a sweep costs two passes over its 133k rays: turning the sensor's
local rays into the world at each column's pose, and turning the first hits into point
records. Written as numpy expressions they took ~1.2 ms and ~2.1 ms per sweep (one core):
13 % on top of a 25 ms cast, and more on two threads, where numpy's many short passes
share the memory bus with Embree. Here each is one pass over the rays (~0.3 ms and
~0.7 ms; ``bench/lidar_traffic.py`` prints the scanner beside raw embreex).

The arithmetic is the float32 arithmetic of the numpy expressions it replaces, in the same
order and without fused multiply-adds (numba's default, no ``fastmath``), so the bytes are
the same: ``d_w = d0 r0 + d1 r1 + d2 r2`` per axis, ``x = o + r d``,
``cos = |d0 n0 + d1 n1 + d2 n2|``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: One row per face-table row: unit normal (the frame of the face's mesh) and its labels.
FACE_DTYPE = np.dtype([("normal", "<f4", (3,)), ("class", "u1"), ("instance", "<u2"), ("material", "<u2")])


@njit(nogil=True, cache=True, boundscheck=False)
def world_rays(o_loc, d_loc, rot_t, trans, c0, c1, o_out, d_out):  # pragma: no cover - compiled
    """Rays of firing columns ``c0 .. c1 - 1`` in the world (re-centred) frame.

    Parameters
    ----------
    o_loc, d_loc : (steps, L, 3) float32
        Emission points and unit directions per column and laser, sensor frame (ring order).
    rot_t : (steps, 3, 3) float32
        Per column the transposed sensor-to-world rotation (row vectors: ``d_w = d @ rot_t``).
    trans : (steps, 3) float32
        Per column the sensor position minus the caster's re-centring point, metres.
    c0, c1 : int
        Column range.
    o_out, d_out : ((c1 - c0) * L, 3) float32
        Written: origins (re-centred) and directions, column-major then laser.
    """
    n_l = o_loc.shape[1]
    k = 0
    for c in range(c0, c1):
        r00, r01, r02 = rot_t[c, 0, 0], rot_t[c, 0, 1], rot_t[c, 0, 2]
        r10, r11, r12 = rot_t[c, 1, 0], rot_t[c, 1, 1], rot_t[c, 1, 2]
        r20, r21, r22 = rot_t[c, 2, 0], rot_t[c, 2, 1], rot_t[c, 2, 2]
        t0, t1, t2 = trans[c, 0], trans[c, 1], trans[c, 2]
        for j in range(n_l):
            a, b, e = d_loc[c, j, 0], d_loc[c, j, 1], d_loc[c, j, 2]
            d_out[k, 0] = a * r00 + b * r10 + e * r20
            d_out[k, 1] = a * r01 + b * r11 + e * r21
            d_out[k, 2] = a * r02 + b * r12 + e * r22
            a, b, e = o_loc[c, j, 0], o_loc[c, j, 1], o_loc[c, j, 2]
            o_out[k, 0] = a * r00 + b * r10 + e * r20 + t0
            o_out[k, 1] = a * r01 + b * r11 + e * r21 + t1
            o_out[k, 2] = a * r02 + b * r12 + e * r22 + t2
            k += 1


@njit(nogil=True, cache=True, boundscheck=False)
def returns(dist, face, min_range, hit):  # pragma: no cover - compiled
    """Mark the misses and list the rays that are points, in one pass.

    Parameters
    ----------
    dist : (n,) float32
        Embree's ``tfar`` per ray, metres; set to ``inf`` where ``face`` is -1 (a miss).
    face : (n,) int32
        Hit face per ray (-1 on a miss).
    min_range : float
        Hits nearer than this are not points (the sensor's minimum range), metres.
    hit : (n,) int64
        Written: the indices of the rays that are points, ascending, in ``hit[:count]``.

    Returns
    -------
    count : int
    """
    k = 0
    lo = np.float32(min_range)
    for i in range(dist.shape[0]):
        if face[i] < 0:
            dist[i] = np.inf
        elif dist[i] >= lo:
            hit[k] = i
            k += 1
    return k


@njit(nogil=True, cache=True, boundscheck=False)
def fill_records(out, hit, ray0, dist, face, d_w, o_loc, d_loc, azimuth, column_time, ring_of, laser_of,
                 faces, skew):  # pragma: no cover - compiled
    """Write one record per hit (see :data:`generator.lidar.points.POINT_DTYPE`).

    Parameters
    ----------
    out : (h,) POINT_DTYPE
        Destination, written in place (``moving`` = 0; the caller marks actors).
    hit : (h,) int64
        Chunk-local indices of the rays that are points.
    ray0 : int
        Sweep index of the chunk's first ray.
    dist : (n,) float32
        Distance to the hit along each ray, metres.
    face : (n,) int32
        Face-table row of each hit.
    d_w : (n, 3) float32
        Beam direction in the frame of the hit face's normal.
    o_loc, d_loc : (rays, 3) float32
        Emission points and directions, sensor frame, sweep ray order.
    azimuth : (rays,) float32
        Beam azimuth per ray, radians.
    column_time : (steps,) float32
        Firing offset per column, seconds.
    ring_of, laser_of : (L,) uint8
        Ring and laser id per position within a column.
    faces : (F,) FACE_DTYPE
    skew : bool
        Write the firing offsets into ``time`` (else 0).
    """
    n_l = ring_of.shape[0]
    zero = np.float32(0.0)
    for i in range(hit.shape[0]):
        r = hit[i]
        q = ray0 + r
        t = dist[r]
        f = faces[face[r]]
        rec = out[i]
        rec.x = o_loc[q, 0] + t * d_loc[q, 0]
        rec.y = o_loc[q, 1] + t * d_loc[q, 1]
        rec.z = o_loc[q, 2] + t * d_loc[q, 2]
        rec.range = t
        col = q // n_l
        rec.azimuth = azimuth[q]
        rec.time = column_time[col] if skew else zero
        c = d_w[r, 0] * f.normal[0]
        c += d_w[r, 1] * f.normal[1]
        c += d_w[r, 2] * f.normal[2]
        rec.cos_incidence = abs(c)
        rec.ring = ring_of[q - col * n_l]
        rec.column = col
        rec.laser = laser_of[q - col * n_l]
        rec["class"] = f["class"]
        rec.instance = f.instance
        rec.material = f.material
        rec.moving = 0
        rec.mixed = 0
        rec.echo = 0
        rec.power = zero


@njit(nogil=True, cache=True, boundscheck=False)
def to_actor_frames(o_w, d_w, ray, pair, position, cos, sin, o_out, d_out):  # pragma: no cover - compiled
    """Rays into the local frames of the actors they may meet (float64, then float32), one pass.

    ``o = o_w - position`` and ``(c o_x + s o_y, c o_y - s o_x, o_z)`` per entry, and the same rotation of
    ``d_w``: the float64 arithmetic of the numpy expressions it replaces, in their order.

    Parameters
    ----------
    o_w, d_w : (n, 3) float32
        Ray origins (minus the static caster's centre) and directions, world axes.
    ray, pair : (m,) int64
        Per entry: the ray and its (candidate, column) pair of the sweep plan.
    position : (P, 3) float64
        Actor origin per pair, minus the static caster's centre.
    cos, sin : (P,) float64
        Cosine and sine of the actor's heading per pair.
    o_out, d_out : (m, 3) float32
        Written: origin and direction in the actor's frame.
    """
    for i in range(ray.shape[0]):
        r, p = ray[i], pair[i]
        c, s = cos[p], sin[p]
        ox = np.float64(o_w[r, 0]) - position[p, 0]
        oy = np.float64(o_w[r, 1]) - position[p, 1]
        oz = np.float64(o_w[r, 2]) - position[p, 2]
        o_out[i, 0] = np.float32(c * ox + s * oy)
        o_out[i, 1] = np.float32(c * oy - s * ox)
        o_out[i, 2] = np.float32(oz)
        dx, dy, dz = np.float64(d_w[r, 0]), np.float64(d_w[r, 1]), np.float64(d_w[r, 2])
        d_out[i, 0] = np.float32(c * dx + s * dy)
        d_out[i, 1] = np.float32(c * dy - s * dx)
        d_out[i, 2] = np.float32(dz)
