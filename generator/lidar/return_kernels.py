"""Compiled loops of the physical return model (:mod:`generator.lidar.returns`): the waveform.

All run with the GIL released on one chunk of firing columns. Ray arrays of a chunk:

* *central* rays: the chunk's columns (plus one halo column each side when beams have sub-rays;
  ``(b - a) * L`` rays, column-major then ring), cast as the ideal scanner casts them;
* the *ray list* the waveform reads: the chunk's own central rays first (inner beam ``q`` is row
  ``q``), then the sub-rays, then the rays continued behind glass; each row names its beam.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from generator.lidar.hashed_normal import normal01
from generator.lidar.returns import MIXED_NORMAL_COS


@njit(nogil=True, cache=True, inline="always")
def _cos_power(c, k):  # pragma: no cover - compiled
    """``c ** k`` for a cosine ``c`` in [0, 1] (float32): the exponents the optics use (1, 1/2, 1/4 and
    whole numbers up to 1024) by square roots and squarings, any other by ``pow`` (a call ~10x dearer)."""
    if k == 1.0:
        return c
    if k == 0.25:
        return np.sqrt(np.sqrt(c))
    if k == 0.5:
        return np.sqrt(c)
    e = np.int64(k)
    if e == k and 1 <= e <= 1024:
        out, base = np.float32(1.0), c
        while e:
            if e & 1:
                out *= base
            base *= base
            e >>= 1
        return out
    return c ** k


@njit(nogil=True, cache=True, inline="always")
def _write(rec, qq, col, ring, t32, o_loc, d_loc, azimuth, column_time, laser_of, n_l, f, cos, inst, moving, mixed,
           echo, power, skew):  # pragma: no cover - compiled
    """One point record (see :data:`generator.lidar.points.POINT_DTYPE`) of sweep ray ``qq`` at range ``t32``."""
    rec.x = o_loc[qq, 0] + t32 * d_loc[qq, 0]
    rec.y = o_loc[qq, 1] + t32 * d_loc[qq, 1]
    rec.z = o_loc[qq, 2] + t32 * d_loc[qq, 2]
    rec.range = t32
    rec.azimuth = azimuth[qq]
    rec.time = column_time[col] if skew else np.float32(0.0)
    rec.cos_incidence = cos
    rec.ring = ring
    rec.column = col
    rec.laser = laser_of[qq - col * n_l]
    rec["class"] = f["class"]
    rec.instance = inst if inst >= 0 else f.instance
    rec.material = f.material
    rec.moving = moving
    rec.mixed = mixed
    rec.echo = echo
    rec.power = power


@njit(nogil=True, cache=True, error_model="numpy")
def beam_returns(out, n_beams, ray0, beam, weight, offset, tau, dist, face, d_f, inst, moving,
                 o_loc, d_loc, azimuth, column_time, ring_of, laser_of, faces,
                 refl, lobe_gain, lobe_exp, r0, r_min, alpha, threshold, separation, dual,
                 min_range, max_range, key, ring_sigma, skew, k_inc):  # pragma: no cover - compiled
    """Every beam's returns from its hits (the waveform); writes records, returns their count.

    Parameters
    ----------
    out : (2 * n_beams,) POINT_DTYPE
        Destination: per beam its strongest return, then (dual) its second.
    n_beams : int
        Inner beams of the chunk; beam ``q`` is sweep ray ``ray0 + q``.
    beam, weight, offset, tau : (n,) int64, float32, float32, float32
        Per ray of the list (rows ``0 .. n_beams - 1``: the central rays, ``beam[q] == q``): its
        beam, share of the beam's power, distance travelled before its origin (behind glass),
        two-way transmission of the glass crossed.
    dist, face, d_f : (n,) float32, (n,) int32, (n, 3) float32
        Hit distance from the ray's origin, face-table row (-1: no hit, or absorbed), direction in
        the frame of the face's normal.
    inst, moving : (n,) int32, uint8
        Actor instance (-1: the face's own) and moving flag.
    o_loc, d_loc, azimuth, column_time, ring_of, laser_of, faces, skew
        As :func:`generator.lidar.kernels.fill_records`.
    refl, lobe_gain, lobe_exp : (M,) float32
        Per material optics.
    r0, r_min, alpha, threshold, separation : float
        Reference range, minimum range of the 1/R^2 law, extinction (1/m), detection threshold,
        merge distance (m).
    k_inc : (M,) float32
        Per material the incidence exponent of its diffuse term (``cos^k_inc``).
    dual : bool
    min_range, max_range : float
        The sensor's.
    key : int
        This frame's noise key.
    ring_sigma : (L,) float32
        Range noise per ring, metres.
    """
    n = beam.shape[0]
    # rows 0 .. n_beams - 1 are the beams' central rays, in order (beam[q] == q); only the rows after
    # them (sub-rays, rays behind glass) are gathered per beam, so a beam without extra rays costs
    # one look at its central row
    total = np.empty(n, np.float64)  # offset + distance: extra rows here, a central row in its beam's turn
    count = np.zeros(n_beams + 1, np.int64)
    extra = np.empty(0, np.int64)
    if n > n_beams:
        for r in range(n_beams, n):
            t = np.float64(offset[r]) + np.float64(dist[r])
            total[r] = t
            if face[r] >= 0 and t >= min_range and t < max_range:
                count[beam[r] + 1] += 1
        for q in range(n_beams):
            count[q + 1] += count[q]
        extra = np.empty(count[n_beams], np.int64)
        fill = count[:n_beams].copy()
        for r in range(n_beams, n):
            if face[r] >= 0 and total[r] >= min_range and total[r] < max_range:
                extra[fill[beam[r]]] = r
                fill[beam[r]] += 1
    n_l = ring_of.shape[0]
    m = 0
    cap = 64
    ev = np.empty(cap, np.int64)
    power = np.empty(cap)
    rng_e = np.empty(cap)
    lab = np.empty(cap, np.int64)
    c_start = np.empty(cap, np.int64)
    c_pow = np.empty(cap)
    c_rng = np.empty(cap)
    c_rep = np.empty(cap, np.int64)
    c_mix = np.zeros(cap, np.bool_)
    for q in range(n_beams):
        t = np.float64(offset[q]) + np.float64(dist[q])
        total[q] = t
        central = face[q] >= 0 and t >= min_range and t < max_range
        lo, hi = count[q], count[q + 1]
        ne = hi - lo + (1 if central else 0)
        if ne == 0:
            continue
        if ne == 1:  # one hit (most beams): no sorting, no clusters
            r = q if central else extra[lo]
            f = faces[face[r]]
            c = abs(d_f[r, 0] * f.normal[0] + d_f[r, 1] * f.normal[1] + d_f[r, 2] * f.normal[2])
            mat = f.material
            t = total[r]
            g = _cos_power(c, k_inc[mat])
            if lobe_gain[mat] > 0:
                g += lobe_gain[mat] * _cos_power(c, lobe_exp[mat])
            rr = r0 / max(t, r_min)
            pw = weight[r] * tau[r] * refl[mat] * g * rr * rr
            if alpha > 0:
                pw *= np.exp(-2.0 * alpha * t)
            if pw < threshold:
                continue
            qq = ray0 + q
            col = qq // n_l
            ring = ring_of[qq - col * n_l]
            rng_out = t + ring_sigma[ring] * normal01(key, qq * 2) if ring_sigma[ring] > 0 else t
            if rng_out < min_range:
                rng_out = min_range
            _write(out[m], qq, col, ring, np.float32(rng_out), o_loc, d_loc, azimuth, column_time, laser_of, n_l,
                   f, np.float32(c), inst[r], moving[r], 0, 0, np.float32(pw), skew)
            m += 1
            continue
        if ne > cap:
            ne = cap
        # the beam's events in row order (its central ray first), at most `cap`
        i = 0
        if central:
            ev[0] = q
            i = 1
        for e in range(lo, hi):
            if i == ne:
                break
            ev[i] = extra[e]
            i += 1
        # insertion sort of the beam's events by range
        for i in range(1, ne):
            e = ev[i]
            j = i - 1
            while j >= 0 and total[ev[j]] > total[e]:
                ev[j + 1] = ev[j]
                j -= 1
            ev[j + 1] = e
        for i in range(ne):
            r = ev[i]
            f = faces[face[r]]
            c = abs(d_f[r, 0] * f.normal[0] + d_f[r, 1] * f.normal[1] + d_f[r, 2] * f.normal[2])
            mat = f.material
            t = total[r]
            g = _cos_power(c, k_inc[mat])
            if lobe_gain[mat] > 0:
                g += lobe_gain[mat] * _cos_power(c, lobe_exp[mat])
            rr = r0 / max(t, r_min)
            power[i] = weight[r] * tau[r] * refl[mat] * g * rr * rr * np.exp(-2.0 * alpha * t)
            rng_e[i] = t
            ins = inst[r] if inst[r] >= 0 else np.int64(f.instance)
            lab[i] = (np.int64(f["class"]) << 16) | ins
        # clusters: events within `separation` of the cluster's first one merge
        nc = 0
        i = 0
        while i < ne:
            j = i
            while j + 1 < ne and rng_e[j + 1] - rng_e[i] <= separation:
                j += 1
            sp, spr = 0.0, 0.0
            for e in range(i, j + 1):
                sp += power[e]
                spr += power[e] * rng_e[e]
            # dominant label: the most power; its strongest event represents the return
            best_lab, best_p = lab[i], -1.0
            for e in range(i, j + 1):
                s = 0.0
                for e2 in range(i, j + 1):
                    if lab[e2] == lab[e]:
                        s += power[e2]
                if s > best_p:
                    best_p, best_lab = s, lab[e]
            rep, rep_p = i, -1.0
            for e in range(i, j + 1):
                if lab[e] == best_lab and power[e] > rep_p:
                    rep, rep_p = e, power[e]
            mixed = False
            nr = faces[face[ev[rep]]].normal
            for e in range(i, j + 1):
                if lab[e] != best_lab:
                    mixed = True
                else:
                    ne_ = faces[face[ev[e]]].normal
                    if abs(ne_[0] * nr[0] + ne_[1] * nr[1] + ne_[2] * nr[2]) < MIXED_NORMAL_COS:
                        mixed = True
            c_start[nc] = i
            c_pow[nc] = sp
            c_rng[nc] = spr / sp if sp > 0 else rng_e[i]
            c_rep[nc] = rep
            c_mix[nc] = mixed
            nc += 1
            i = j + 1
        # strongest detected, last detected, second strongest
        s1, s2, last = -1, -1, -1
        for k in range(nc):
            if c_pow[k] < threshold:
                continue
            last = k
            if s1 < 0 or c_pow[k] > c_pow[s1]:
                s2 = s1
                s1 = k
            elif s2 < 0 or c_pow[k] > c_pow[s2]:
                s2 = k
        if s1 < 0:
            continue
        picks = (s1, (last if last != s1 else s2) if dual else -1)
        qq = ray0 + q
        col = qq // n_l
        ring = ring_of[qq - col * n_l]
        for echo in range(2):
            k = picks[echo]
            if k < 0:
                continue
            r = ev[c_rep[k]]
            f = faces[face[r]]
            rng_out = c_rng[k] + ring_sigma[ring] * normal01(key, qq * 2 + echo)
            if rng_out < min_range:
                rng_out = min_range
            c = d_f[r, 0] * f.normal[0]
            c += d_f[r, 1] * f.normal[1]
            c += d_f[r, 2] * f.normal[2]
            _write(out[m], qq, col, ring, np.float32(rng_out), o_loc, d_loc, azimuth, column_time, laser_of, n_l, f,
                   np.float32(abs(c)), inst[r], moving[r], 1 if c_mix[k] else 0, echo, np.float32(c_pow[k]), skew)
            m += 1
    return m

