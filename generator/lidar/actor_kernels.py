"""Compiled passes of :class:`generator.lidar.actors.ActorCaster` per chunk (GIL released): the beams a
chunk aims at the actors (:func:`aim_entries`), and around ``cast``'s Embree calls (:func:`reaching`,
:func:`nearest_hits`).

``cast`` runs up to three times per chunk of a physical sweep (central rays, sub-rays, rays behind
glass) on the ~10-40k (beam, actor) entries of the chunk's actor windows. As numpy expressions its
culls and its nearest-hit pick (a lexsort) were a dozen short passes holding the GIL, ~7 ms of CPU per
sweep of the default town with 120 moving actors (one thread); here they are two passes. The
comparisons are those of the numpy expressions, in float32 (``dist + offset`` added in float32, then
compared with the float32 ``near``), and a ray's nearest hit is picked with ties going to the first
entry in prototype then entry order, as the stable lexsort did: the bytes are the same.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(nogil=True, cache=True)
def reaching(ray, pair, cand, ptr, ids, dist, offset, near, use_rows, use_offset):  # pragma: no cover - compiled
    """The (ray, pair, candidate) entries whose ray reaches beyond the actor's nearest distance.

    Parameters
    ----------
    ray, pair, cand : (m,) int64
        :meth:`~generator.lidar.actors.ActorCaster.aim`'s entries: beam, (candidate, column) pair, candidate.
    ptr, ids : (beams + 1,) int64, (n,) int64
        With ``use_rows``: beam ``q``'s rays are ``ids[ptr[q]:ptr[q + 1]]`` (entries are expanded to
        them, beam by beam, in that order); otherwise ``ray`` names the rays and these are unused.
    dist, offset : (n,) float32
        Static hit distance per ray; with ``use_offset``, the distance of its origin along its beam.
    near : (P,) float32
        Nearest distance of the pair's actor from the sensor.

    Returns
    -------
    ray, pair, cand : (k,) int64
        The entries (rays, not beams) with ``dist (+ offset) > near``, in entry order.
    """
    m = ray.shape[0]
    total = 0
    if use_rows:
        for i in range(m):
            total += ptr[ray[i] + 1] - ptr[ray[i]]
    else:
        total = m
    r_out, p_out, c_out = np.empty(total, np.int64), np.empty(total, np.int64), np.empty(total, np.int64)
    k = 0
    for i in range(m):
        p = pair[i]
        lo, hi = (ptr[ray[i]], ptr[ray[i] + 1]) if use_rows else (i, i + 1)
        for e in range(lo, hi):
            r = ids[e] if use_rows else ray[i]
            reach = dist[r] + offset[r] if use_offset else dist[r]
            if reach > near[p]:
                r_out[k], p_out[k], c_out[k] = r, p, cand[i]
                k += 1
    return r_out[:k], p_out[:k], c_out[:k]


@njit(nogil=True, cache=True)
def nearest_hits(ray, pair, cand, t, prim, proto, proto_face_offset, d_loc, plan_actor, plan_moving,
                 dist, face, d_w):  # pragma: no cover - compiled
    """Each ray's nearest actor hit replaces its static one (arrays updated in place).

    Of equal hits on one ray the entry of the lower prototype wins, then the earlier entry: the pick of the
    casts grouped by prototype (a stable sort) that this replaced, so the bytes are the same.

    Parameters
    ----------
    ray, pair, cand : (k,) int64
        Per entry: its ray, (candidate, column) pair and candidate.
    t, prim : (k,) float32, int32
        Per entry: hit distance and the prototype's face (-1: none).
    proto : (k,) int64
        Prototype per entry.
    proto_face_offset : (n_protos,) int64
    d_loc : (k, 3) float32
        Per entry: the direction in its actor's frame.
    plan_actor, plan_moving : (K,) int64, (P,) uint8
        :class:`~generator.lidar.actors.SweepPlan`'s ``actor`` and ``moving``.
    dist, face, d_w : (n,) float32, (n,) int32, (n, 3) float32
        The rays' hits, updated where an actor is hit.

    Returns
    -------
    count : int
        Rays that hit an actor.
    actor, moving : (n,) int32, uint8
        Actor index per ray (-1: the town) and its moving flag.
    """
    n = dist.shape[0]
    best = np.full(n, np.inf, np.float32)
    win = np.full(n, -1, np.int64)
    for j in range(ray.shape[0]):
        if prim[j] < 0:
            continue
        r = ray[j]
        w = win[r]
        if w < 0 or t[j] < best[r] or (t[j] == best[r] and proto[j] < proto[w]):
            best[r] = t[j]
            win[r] = j
    actor = np.full(n, -1, np.int32)
    moving = np.zeros(n, np.uint8)
    count = 0
    for r in range(n):
        j = win[r]
        if j < 0:
            continue
        dist[r] = t[j]
        face[r] = prim[j] + proto_face_offset[proto[j]]
        d_w[r, 0], d_w[r, 1], d_w[r, 2] = d_loc[j, 0], d_loc[j, 1], d_loc[j, 2]
        actor[r] = plan_actor[cand[j]]
        moving[r] = plan_moving[pair[j]]
        count += 1
    return count, actor, moving


@njit(nogil=True, cache=True)
def aim_entries(c0, c1, pair_off, ring0, ring1, azimuth, half, psi, rot, start, stop, n_l):  # pragma: no cover
    """:meth:`~generator.lidar.actors.ActorCaster.aim`'s entries in one pass (its numpy arithmetic, float64).

    Parameters
    ----------
    c0, c1, pair_off, ring0, ring1, azimuth, half
        :class:`~generator.lidar.actors.SweepPlan`'s arrays.
    psi, rot : (steps,) float64, (L,) float64
        :class:`~generator.lidar.windows.BeamTable`'s encoder azimuth per column and rotation per ring.
    start, stop : int
        The chunk's firing columns ``[start, stop)``.
    n_l : int
        Lasers.

    Returns
    -------
    beam, pair, cand : (m,) int64
        Chunk beam ``(column - start) * n_l + ring``, (candidate, column) pair and candidate of every
        beam whose azimuth lies within the pair's window, by candidate, column, ring.
    """
    total = 0
    for k in range(c0.shape[0]):
        for col in range(max(c0[k], start), min(c1[k], stop)):
            p = pair_off[k] + (col - c0[k])
            total += max(ring1[p] - ring0[p], 0)
    beam, pair, cand = np.empty(total, np.int64), np.empty(total, np.int64), np.empty(total, np.int64)
    two_pi = 2 * np.pi
    m = 0
    for k in range(c0.shape[0]):
        for col in range(max(c0[k], start), min(c1[k], stop)):
            p = pair_off[k] + (col - c0[k])
            for ring in range(ring0[p], ring1[p]):
                off = psi[col] + rot[ring] - azimuth[p] + np.pi  # this laser's beam vs the actor's direction
                # np.mod(off, 2 pi) is off itself on [0, 2 pi): fmod, a libm call, only outside
                wrapped = off if off >= 0.0 and off < two_pi else np.mod(off, two_pi)
                if abs(wrapped - np.pi) <= half[p]:
                    beam[m], pair[m], cand[m] = (col - start) * n_l + ring, p, k
                    m += 1
    return beam[:m], pair[:m], cand[:m]
