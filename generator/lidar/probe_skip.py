"""Which probe sub-rays need not be cast: those that land on their centre's own triangle with nothing their
neighbour sees in front of it (:func:`probes_on_centre`, used by :mod:`generator.lidar.physical_chunk`).

Compiled like :mod:`generator.lidar.return_rays`, on the float32 triangle corners Embree holds
(:meth:`generator.lidar.caster.EmbreeCaster.triangle_corners`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: barycentric margin inside which a probe counts as landing on its centre's triangle (Embree's own hit)
ON_TRIANGLE_MARGIN = 1e-3


@njit(nogil=True, cache=True, inline="always")
def _normal(corners, f):  # pragma: no cover - compiled
    """``e1 x e2`` and its squared length for face ``f`` (float64; ``e1, e2`` its edges from its first corner)."""
    ax, ay, az = np.float64(corners[f, 0, 0]), np.float64(corners[f, 0, 1]), np.float64(corners[f, 0, 2])
    e1x, e1y, e1z = corners[f, 1, 0] - ax, corners[f, 1, 1] - ay, corners[f, 1, 2] - az
    e2x, e2y, e2z = corners[f, 2, 0] - ax, corners[f, 2, 1] - ay, corners[f, 2, 2] - az
    nx, ny, nz = e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x
    return nx, ny, nz, nx * nx + ny * ny + nz * nz


@njit(nogil=True, cache=True)
def probes_on_centre(pb, pw, edge, side, probes, o_w, d_w, p_o, p_d, dist, face, corners, lo, hi, step_m, step_rel,
                     n_l, out):  # pragma: no cover - compiled
    """Probes that land on their centre's own triangle where nothing their neighbour sees can stand in front.

    Such a probe sees the centre's surface (unless a surface that neither the beam's centre nor that
    neighbour touches lies within its reach), as the sub-rays towards neighbours that see the centre's
    surface are taken to: it would not split its beam, so it need not be cast. A probe qualifies when

    * its line meets the centre's triangle (a town face; actors' faces are not tested) inside it by
      :data:`ON_TRIANGLE_MARGIN` (barycentric), at a range within the split step of the centre's less
      1 mm + 1e-4 of the range (float rounding cannot decide), and
    * every neighbour on its side has no hit, or a hit that cannot stand between the sensor and that
      point: behind the centre's triangle's plane along its own ray, or (a town face) on a plane the
      probe's line does not cross before it (1 mm + 1e-4 of the range of slack either way). A neighbour
      on the centre's plane fails both (a class boundary on one plane, such as road and parking, is
      probed: paint or a kerb may lie on the boundary).

    Float64 arithmetic on the float32 rays and corners Embree casts.

    Parameters
    ----------
    pb, pw : (m,) int64
        Probe pairs (:func:`probe_pairs`), by beam.
    edge, side : (e,) int64, uint8
        :func:`~generator.lidar.return_rays.edge_beams`' output (every beam of ``pb`` is in ``edge``).
    probes : (4,) int64
        Sub-ray towards each neighbour (:func:`generator.lidar.returns.probe_index`).
    o_w, d_w : (n, 3) float32
        Central rays (halo rows): re-centred origins and world directions.
    p_o, p_d : (m, 3) float32
        The probes' origins and directions (:func:`~generator.lidar.return_rays.subrays`).
    dist, face : (n,) float32, int32
        Central rays' hits, actors included (a miss: ``face`` -1).
    corners : (F, 3, 3) float32
        The town's triangles as cast (:meth:`generator.lidar.caster.EmbreeCaster.triangle_corners`); face-table
        rows from ``F`` on are actors'.
    lo, hi, step_m, step_rel : float
        The sensor's range window; the split step (:func:`~generator.lidar.return_rays.split_beams`).
    n_l : int
        Lasers.
    out : (m,) bool
        Written: the probe lands on its centre's triangle (need not be cast).

    Returns
    -------
    count : int
        Probes that land on their centre's triangle.
    """
    n_static = corners.shape[0]
    j = 0
    count = 0
    eps = ON_TRIANGLE_MARGIN
    for i in range(pb.shape[0]):
        r = pb[i]
        while edge[j] != r:
            j += 1
        out[i] = False
        f = face[r]
        d = np.float64(dist[r])
        if f < 0 or f >= n_static or not (d >= lo and d < hi):
            continue
        ax, ay, az = np.float64(corners[f, 0, 0]), np.float64(corners[f, 0, 1]), np.float64(corners[f, 0, 2])
        e1x, e1y, e1z = corners[f, 1, 0] - ax, corners[f, 1, 1] - ay, corners[f, 1, 2] - az
        e2x, e2y, e2z = corners[f, 2, 0] - ax, corners[f, 2, 1] - ay, corners[f, 2, 2] - az
        dx, dy, dz = np.float64(p_d[i, 0]), np.float64(p_d[i, 1]), np.float64(p_d[i, 2])
        ox, oy, oz = np.float64(p_o[i, 0]), np.float64(p_o[i, 1]), np.float64(p_o[i, 2])
        # Moeller-Trumbore
        px, py, pz = dy * e2z - dz * e2y, dz * e2x - dx * e2z, dx * e2y - dy * e2x
        det = e1x * px + e1y * py + e1z * pz
        nx, ny, nz = e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x
        n2 = nx * nx + ny * ny + nz * nz
        if not det * det > 1e-12 * n2:  # degenerate, or seen edge-on
            continue
        inv = 1.0 / det
        tx, ty, tz = ox - ax, oy - ay, oz - az
        u = (tx * px + ty * py + tz * pz) * inv
        if u < eps or u > 1.0 - eps:
            continue
        qx, qy, qz = ty * e1z - tz * e1y, tz * e1x - tx * e1z, tx * e1y - ty * e1x
        v = (dx * qx + dy * qy + dz * qz) * inv
        if v < eps or u + v > 1.0 - eps:
            continue
        t = (e2x * qx + e2y * qy + e2z * qz) * inv
        slack = 1e-3 + 1e-4 * d
        if not (abs(t - d) < step_m + step_rel * d - slack and t >= lo + slack and t < hi - slack):
            continue
        ok = True
        s = side[j]
        for bit in range(4):
            if not (s >> bit) & 1 or probes[bit] != pw[i]:
                continue
            rn = r - n_l if bit == 0 else (r + n_l if bit == 1 else (r - 1 if bit == 2 else r + 1))
            fn = face[rn]
            if fn < 0:  # the neighbour sees nothing: nothing stands in front on that side
                continue
            dn = np.float64(dist[rn])
            nd = nx * d_w[rn, 0] + ny * d_w[rn, 1] + nz * d_w[rn, 2]
            if nd * nd > 1e-12 * n2:  # behind the centre's plane along its own ray
                t_plane = (nx * (ax - o_w[rn, 0]) + ny * (ay - o_w[rn, 1]) + nz * (az - o_w[rn, 2])) / nd
                if t_plane >= 0.0 and dn > t_plane + (1e-3 + 1e-4 * dn):
                    continue
            if fn >= n_static:
                ok = False
                break
            mx, my, mz, m2 = _normal(corners, fn)  # or on a plane the probe's line does not cross before its hit
            pd_ = mx * dx + my * dy + mz * dz
            if pd_ * pd_ > 1e-12 * m2:
                t_cross = (mx * (corners[fn, 0, 0] - ox) + my * (corners[fn, 0, 1] - oy)
                           + mz * (corners[fn, 0, 2] - oz)) / pd_
                if t_cross > 0.0 and t_cross < t + slack:
                    ok = False
                    break
        out[i] = ok
        if ok:
            count += 1
    return count


@njit(nogil=True, cache=True)
def drop_on_centre(on, pb, pw, p_o, p_d):  # pragma: no cover - compiled
    """Move the probes to cast (``on`` False) to the front of ``pb, pw, p_o, p_d``, in order, in place.

    One pass instead of four numpy gathers (``x[flatnonzero(~on)]``), which held the GIL.

    Parameters
    ----------
    on : (m,) bool
        :func:`probes_on_centre`'s output.
    pb, pw : (m,) int64
    p_o, p_d : (m, 3) float32
        Updated in place: rows ``[:count]`` are the probes to cast.

    Returns
    -------
    count : int
    """
    k = 0
    for i in range(on.shape[0]):
        if on[i]:
            continue
        if k != i:
            pb[k], pw[k] = pb[i], pw[i]
            for c in range(3):
                p_o[k, c] = p_o[i, c]
                p_d[k, c] = p_d[i, c]
        k += 1
    return k
