"""Compiled passes over a chunk's ray lists (:mod:`generator.lidar.physical_chunk`): edge beams, sub-rays,
probes, splits, panes.

Each replaces a run of numpy expressions that held the GIL, with the same float32 arithmetic in the
same order (no ``fastmath``, so no fused multiply-adds): the points stay byte for byte those of the
numpy version. Labels are ``class << 16 | instance`` (:class:`generator.lidar.physical_chunk.FaceLookup`).
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(nogil=True, cache=True)
def pane_rays(face, dist, offset, tau, inst, o, dw, glass_face, face_trans, face_label, max_range, step_m,
              rows, o_out, off_out, tau_out, left_out, pane_out):  # pragma: no cover - compiled
    """The rays of a ray list that end on a pane, continued from just behind it (one pass).

    The float32 arithmetic of the numpy expressions it replaces, in their order: ``step = dist + step_m``,
    ``o' = o + step d``, ``offset' = offset + step``, ``tau' = tau t t``, ``left = max(R - offset', 1 mm)``.

    Parameters
    ----------
    face, dist, offset, tau, inst : (n,) int32, float32, float32, float32, int32
        The ray list (:func:`generator.lidar.return_kernels.beam_returns`); ``inst`` -1 = the face's own instance.
    o, dw : (n, 3) float32
        Re-centred origins and world directions.
    glass_face : (F + 1,) bool
        Per face-table row: its material lets light through (the last entry, for ``face`` -1, False).
    face_trans : (F + 1,) float32
        Per face-table row its material's one-way transmittance.
    face_label : (F + 1,) int64
        Per face-table row ``class << 16 | instance`` (instance of the face table).
    max_range, step_m : float32
        The sensor's maximum range; how far behind the pane the continued ray starts, metres.
    rows : (n,) int64
        Written: the rows that end on a pane (before ``max_range`` from the sensor), ascending.
    o_out : (n, 3) float32
    off_out, tau_out, left_out : (n,) float32
        Written beside ``rows``: the continued ray's origin, the distance from the sensor to it, the
        two-way transmission so far, and the range it has left (at least 1 mm).
    pane_out : (n,) int64
        Written: ``class << 16 | instance`` of the pane (a ray meeting it again is absorbed).

    Returns
    -------
    count : int
    """
    k = 0
    for r in range(face.shape[0]):
        f = face[r]
        if f < 0 or not glass_face[f] or not offset[r] + dist[r] < max_range:
            continue
        step = dist[r] + step_m
        o_out[k, 0] = o[r, 0] + step * dw[r, 0]
        o_out[k, 1] = o[r, 1] + step * dw[r, 1]
        o_out[k, 2] = o[r, 2] + step * dw[r, 2]
        off = offset[r] + step
        off_out[k] = off
        t = face_trans[f]
        tau_out[k] = tau[r] * t * t
        left = max_range - off
        left_out[k] = left if left > np.float32(1e-3) else np.float32(1e-3)
        pane_out[k] = (face_label[f] & ~np.int64(0xFFFF)) | np.int64(inst[r]) if inst[r] >= 0 else face_label[f]
        rows[k] = r
        k += 1
    return k


@njit(nogil=True, cache=True)
def absorb_interior(face, inst, pane, face_label, face_trans, interior):  # pragma: no cover - compiled
    """Rays behind a pane that its object absorbs end there: ``face`` = -1.

    Behind the pane of a class with a modelled cabin (``interior``), the ray keeps only an opaque face
    of the pane's own object (the cabin seen through its glass); its own glass again (the far window)
    or any other object (a seam of the body) absorbs it, so it never leaves the vehicle. Behind any
    other pane, a ray meeting the pane's own object (same class and instance) is absorbed.

    Parameters
    ----------
    face : (n,) int32
        Hits of the continued rays, updated in place.
    inst : (n,) int32
        Actor instance per hit (-1: the face's own).
    pane : (n,) int64
        Label of the pane each ray crossed (:func:`pane_rays`).
    face_label : (F + 1,) int64
    face_trans : (F + 1,) float32
        Per face-table row its material's one-way transmittance (> 0: glass).
    interior : (C,) bool
        Per class id: its cabin is modelled behind its glass.
    """
    for r in range(face.shape[0]):
        f = face[r]
        if f < 0:
            continue
        lab = (face_label[f] & ~np.int64(0xFFFF)) | np.int64(inst[r]) if inst[r] >= 0 else face_label[f]
        if interior[pane[r] >> 16]:
            if lab != pane[r] or face_trans[f] > 0:
                face[r] = -1
        elif lab == pane[r]:
            face[r] = -1


@njit(nogil=True, cache=True)
def probe_pairs(edge, side, probes, beam_out, which_out):  # pragma: no cover - compiled
    """The probe sub-rays of the edge beams: per beam the sub-ray towards each neighbour that differs.

    Parameters
    ----------
    edge, side : (e,) int64, uint8
        :func:`edge_beams`' output (beams ascending, neighbour bits).
    probes : (4,) int64
        Sub-ray towards each neighbour (:func:`generator.lidar.returns.probe_index`).
    beam_out, which_out : (4 e,) int64
        Written: (beam row, sub-ray) pairs without repeats, by beam then sub-ray.

    Returns
    -------
    count : int
    """
    m = 0
    for i in range(edge.shape[0]):
        start = m
        for b in range(4):
            if (side[i] >> b) & 1:
                w = probes[b]
                j = m
                while j > start and which_out[j - 1] > w:  # insertion, ascending, without repeats
                    j -= 1
                if j > start and which_out[j - 1] == w:
                    continue
                for t in range(m, j, -1):
                    which_out[t] = which_out[t - 1]
                which_out[j] = w
                m += 1
        for t in range(start, m):
            beam_out[t] = edge[i]
    return m


@njit(nogil=True, cache=True)
def _label(f, ins, face_label):  # pragma: no cover - compiled
    return (face_label[f] & ~np.int64(0xFFFF)) | np.int64(ins) if ins >= 0 else face_label[f]


@njit(nogil=True, cache=True)
def split_beams(pb, pw, dist, face, inst, p_dist, p_face, p_inst, face_label, lo, hi, step_m, step_rel, k,
                keep, split, rest_beam, rest_which):  # pragma: no cover - compiled
    """Which edge beams the probes split, and the sub-rays those beams still need.

    A beam splits when a probe sees another class or instance than its centre (a miss, or a hit out of
    ``[lo, hi)``, counting as none), or the same surface more than ``step_m + step_rel * range`` nearer
    or farther (float32, as the numpy expression it replaces).

    Parameters
    ----------
    pb, pw : (m,) int64
        Probe pairs (:func:`probe_pairs`), by beam.
    dist, face, inst : (n,) float32, int32, int32
        Central rays (halo rows).
    p_dist, p_face, p_inst : (m,) float32, int32, int32
        The probes' hits.
    face_label : (F + 1,) int64
    lo, hi, step_m, step_rel : float32
    k : int
        Sub-rays per beam besides the centre.
    keep : (m,) bool
        Written: the probe belongs to a split beam.
    split : (m,) int64
        Written: the split beams, ascending, in ``split[:n_split]``.
    rest_beam, rest_which : (m * k,) int64
        Written: their sub-rays not yet cast, by beam then sub-ray, in ``[:n_rest]``.

    Returns
    -------
    n_split, n_rest : int
    """
    m = pb.shape[0]
    n_split = 0
    n_rest = 0
    have = np.zeros(k, np.bool_)
    i = 0
    while i < m:
        j = i
        while j < m and pb[j] == pb[i]:
            j += 1
        r = pb[i]
        d = dist[r]
        c_lab = _label(face[r], inst[r], face_label) if face[r] >= 0 and d >= lo and d < hi else np.int64(-1)
        bad = False
        for e in range(i, j):
            pd = p_dist[e]
            p_lab = (_label(p_face[e], p_inst[e], face_label) if p_face[e] >= 0 and pd >= lo and pd < hi
                     else np.int64(-1))
            if p_lab != c_lab or (c_lab >= 0 and abs(pd - d) > step_m + step_rel * d):
                bad = True
        for e in range(i, j):
            keep[e] = bad
        if bad:
            split[n_split] = r
            n_split += 1
            have[:] = False
            for e in range(i, j):
                have[pw[e]] = True
            for w in range(k):
                if not have[w]:
                    rest_beam[n_rest] = r
                    rest_which[n_rest] = w
                    n_rest += 1
        i = j
    return n_split, n_rest


@njit(nogil=True, cache=True)
def edge_beams(dist, face, inst, faces, a, c0, c1, n_l, min_range, max_range, step, out, side):  # pragma: no cover
    """Inner beams whose footprint may straddle an edge (see :mod:`generator.lidar.returns`).

    A beam is an edge beam when a neighbour in the range image (the next column either side, the
    next ring up or down) has no return where it has one or the other way round, hits another class or
    instance, or -- the columns either side -- lies more than ``step`` times its range nearer or farther.

    Parameters
    ----------
    dist, face, inst : (n,) float32, int32, int32
        Central rays of columns ``a .. b - 1`` (``inst`` -1 = the face's own instance).
    faces : (F,) FACE_DTYPE
    a, c0, c1 : int
        First halo column and the chunk's columns ``[c0, c1)``.
    n_l : int
        Lasers.
    step : float
        Relative range step between neighbouring columns that counts as an edge.
    out : (n_inner,) int64
        Written: halo-row indices of the edge beams, ascending.
    side : (n_inner,) uint8
        Written beside ``out``: which neighbours differ, bits 1 = previous column, 2 = next column,
        4 = ring above, 8 = ring below.

    Returns
    -------
    count : int
    """
    n = dist.shape[0]
    b = n // n_l + a
    key = np.empty(n, np.int64)
    for r in range(n):
        f = face[r]
        if f < 0 or dist[r] < min_range or dist[r] >= max_range:
            key[r] = -1
        else:
            ins = np.int64(inst[r]) if inst[r] >= 0 else np.int64(faces[f].instance)
            key[r] = (np.int64(faces[f]["class"]) << 16) | ins
    k = 0
    for c in range(c0, c1):
        base = (c - a) * n_l
        for j in range(n_l):
            r = base + j
            own = key[r]
            bits = 0
            if c > a:
                rn = r - n_l
                if key[rn] != own or (own >= 0 and abs(dist[rn] - dist[r]) > step * dist[r]):
                    bits |= 1
            if c + 1 < b:
                rn = r + n_l
                if key[rn] != own or (own >= 0 and abs(dist[rn] - dist[r]) > step * dist[r]):
                    bits |= 2
            if j > 0 and key[r - 1] != own:
                bits |= 4
            if j + 1 < n_l and key[r + 1] != own:
                bits |= 8
            if bits:
                out[k] = r
                side[k] = bits
                k += 1
    return k


@njit(nogil=True, cache=True)
def subrays(o_w, d_w, beams, which, pattern, o_out, d_out):  # pragma: no cover - compiled
    """Sub-rays ``d + x u + y v`` (normalised; ``u`` horizontal to the left of the beam, ``v`` up across it).

    Parameters
    ----------
    o_w, d_w : (n, 3) float32
        Central rays (re-centred origins, world directions).
    beams, which : (m,) int64
        Per sub-ray: the row of its beam and its index in ``pattern``.
    pattern : (K - 1, 2) float64
        Angular offsets ``(x, y)``, radians.
    o_out, d_out : (m, 3) float32
        Written.
    """
    for i in range(beams.shape[0]):
        r = beams[i]
        dx, dy, dz = np.float64(d_w[r, 0]), np.float64(d_w[r, 1]), np.float64(d_w[r, 2])
        h = np.sqrt(dx * dx + dy * dy)
        if h < 1e-9:
            ux, uy, uz = 0.0, 1.0, 0.0
        else:
            ux, uy, uz = -dy / h, dx / h, 0.0
        vx, vy, vz = dy * uz - dz * uy, dz * ux - dx * uz, dx * uy - dy * ux
        px, py = pattern[which[i], 0], pattern[which[i], 1]
        ex, ey, ez = dx + px * ux + py * vx, dy + px * uy + py * vy, dz + px * uz + py * vz
        n = np.sqrt(ex * ex + ey * ey + ez * ez)
        o_out[i, 0], o_out[i, 1], o_out[i, 2] = o_w[r, 0], o_w[r, 1], o_w[r, 2]
        d_out[i, 0], d_out[i, 1], d_out[i, 2] = ex / n, ey / n, ez / n
