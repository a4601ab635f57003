"""One chunk of firing columns under the physical return model (:mod:`generator.lidar.returns`).

Steps, per chunk ``[c0, c1)`` of a sweep (the scanner's threads run chunks in parallel):

1. the central rays of ``[c0 - 1, c1 + 1)`` (one halo column each side, so a beam's neighbours are
   known whatever the chunking) against the town, then the actors, as the ideal scanner casts them;
   which beams may meet which actor (:meth:`generator.lidar.actors.ActorCaster.aim`) is worked out
   once here and reused by every later ray list of the chunk;
2. the chunk's edge beams (:func:`generator.lidar.return_rays.edge_beams`) get their probe
   sub-rays (:func:`~generator.lidar.return_rays.probe_pairs`); those that land on their centre's own
   triangle with nothing their neighbour sees in front (:func:`~generator.lidar.probe_skip.probes_on_centre`)
   are not cast, the others are, against the town and the actors; the beams the cast probes split
   (:func:`~generator.lidar.return_rays.split_beams`) keep them, and their other sub-rays (the uncast
   probes among them) either take the centre's hit (``edge_subrays: differing``) or are cast too (``all``);
3. rays that end on glass go on behind it, up to ``glass_layers`` panes
   (:func:`~generator.lidar.return_rays.pane_rays`); a continued ray that meets the object whose
   glass it crossed (same class and instance) is absorbed in its interior, unless the object's cabin
   is modelled: then only its own opaque faces return it
   (:func:`~generator.lidar.return_rays.absorb_interior`);
4. the waveform of every beam (:func:`generator.lidar.return_kernels.beam_returns`) gives its
   returns, handed to the sweep (:meth:`generator.lidar.sweep_flight.SweepInFlight.deliver`), which places them
   once the chunks before have counted theirs: no chunk waits for another.

Per-hit work runs in compiled passes with the GIL released; what stays in numpy is per chunk, not
per ray list row. Every step keeps the float32 arithmetic and the order of the numpy version it
replaced, so the points are those of the code before, byte for byte.
"""

from __future__ import annotations

import numpy as np

from generator.lidar.kernels import world_rays
from generator.lidar.points import POINT_DTYPE
from generator.lidar.probe_skip import drop_on_centre, probes_on_centre
from generator.lidar.return_kernels import beam_returns
from generator.lidar.return_rays import (
    absorb_interior,
    edge_beams,
    pane_rays,
    probe_pairs,
    split_beams,
    subrays,
)

#: how far behind a pane a continued ray starts, metres
GLASS_STEP_M = 1e-3
#: a probe sub-ray whose range differs from its centre's by more than this (metres + share of the
#: range) splits its beam: the footprint does not lie on one smooth surface
SPLIT_STEP_M, SPLIT_STEP_REL = 0.05, 0.01


def _actor_hits(scanner, plan, cols, o, d, dist, face, aimed, rows=None, offset=None):
    """Actors occlude the rays (arrays updated in place); returns per-ray (instance or -1, moving).

    ``aimed`` is :meth:`generator.lidar.actors.ActorCaster.aim` of ``cols``, computed once per chunk.
    """
    inst = np.full(len(dist), -1, np.int32)
    moving = np.zeros(len(dist), np.uint8)
    if plan is None or aimed is None or len(dist) == 0:
        return inst, moving
    hit = scanner.actors.cast(plan, cols, o, d, dist, face, rows=rows, offset=offset, aimed=aimed)
    if hit is not None:
        actor, mov = hit
        m = np.flatnonzero(actor >= 0)
        inst[m] = scanner.actors.instance[actor[m]]
        moving[m] = mov[m]
    return inst, moving


def _cast_subrays(scanner, plan, cols, aimed, o, d, beam_rows, i0, n_in, max_range) -> dict:
    """Cast the sub-rays ``o, d`` (:func:`~generator.lidar.return_rays.subrays` of ``beam_rows``, ordered by
    beam) against the town and the actors."""
    m = len(beam_rows)
    dw = d.copy()
    dist, face = scanner.caster.intersect_local(o, d, max_range, mark_misses=False)
    beam = beam_rows - i0
    ptr = np.zeros(n_in + 1, np.int64)
    ptr[1:] = np.bincount(beam, minlength=n_in)
    inst, moving = _actor_hits(scanner, plan, cols, o, d, dist, face, aimed, rows=(np.cumsum(ptr), np.arange(m)))
    return {"o": o, "dw": dw, "df": d, "dist": dist, "face": face, "inst": inst, "moving": moving, "beam": beam}


def _subray_rays(o_w, d_world, beam_rows, which, pattern) -> tuple[np.ndarray, np.ndarray]:
    """(m, 3) float32 origins and directions of the sub-rays ``(beam_rows, which)``."""
    m = len(beam_rows)
    o, d = np.empty((m, 3), np.float32), np.empty((m, 3), np.float32)
    subrays(o_w, d_world, beam_rows, which, pattern, o, d)
    return o, d


def central_constants(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Read-only (n,) float32 zeros and ones and int64 ``0 .. n - 1``: the central rays' offset, glass
    transmission and beam (:attr:`generator.lidar.scan.Scanner.central_constants`, made once per scanner
    for its largest chunk instead of once per chunk and sweep)."""
    c = (np.zeros(n, np.float32), np.ones(n, np.float32), np.arange(n, dtype=np.int64))
    for a in c:
        a.flags.writeable = False
    return c


def run_physical_chunk(scanner, sweep, i: int, cols: slice) -> None:
    """Cast chunk ``i`` (columns ``cols``) of ``sweep`` and write its returns (see the module docstring)."""
    sensor, model, tables = scanner.sensor, scanner.returns, scanner._records
    p, opt = model.params, model.optics
    L, steps = sensor.n_lasers, sensor.azimuth_steps
    lo_r, hi_r = float(sensor.min_range_m), float(sensor.max_range_m)
    faces = tables._faces
    try:
        k = len(model.pattern)
        # one halo column each side tells an edge beam from its neighbours (only sub-rays need it)
        a, b = (max(0, cols.start - 1), min(steps, cols.stop + 1)) if k else (cols.start, cols.stop)
        n = (b - a) * L
        o_w, d_w = np.empty((n, 3), np.float32), np.empty((n, 3), np.float32)
        world_rays(scanner._o32, scanner._d32, sweep.rot_t, sweep.trans, a, b, o_w, d_w)
        # the actors replace the directions of their hits by local ones: sub-rays and rays behind glass
        # start from a copy of the world directions
        d_world = d_w.copy() if k or p.glass_layers else d_w
        dist, face = scanner.caster.intersect_local(o_w, d_w, hi_r, mark_misses=False)
        plan = sweep.get_plan()
        # which beams may meet which actor: once per chunk, for the central rays, the sub-rays and the glass
        aimed = scanner.actors.aim(plan, slice(a, b)) if plan is not None else None
        inst, moving = _actor_hits(scanner, plan, slice(a, b), o_w, d_w, dist, face, aimed)
        i0, i1 = (cols.start - a) * L, (cols.stop - a) * L
        n_in = i1 - i0
        aimed = scanner.actors.inner(aimed, i0, n_in) if plan is not None else None
        n_edge = 0
        if k:  # without sub-rays (one ray per beam) no beam needs to know its neighbours
            edge, side = np.empty(n_in, np.int64), np.empty(n_in, np.uint8)
            n_edge = edge_beams(dist, face, inst, faces, a, cols.start, cols.stop, L, lo_r, hi_r, p.edge_step, edge,
                                side)
            edge, side = edge[:n_edge], side[:n_edge]
        weight = np.ones(n_in, np.float32)
        zeros, ones, rows = (c[:n_in] for c in scanner.central_constants)
        parts = {"o": [o_w[i0:i1]], "dw": [d_world[i0:i1]], "df": [d_w[i0:i1]], "dist": [dist[i0:i1]],
                 "face": [face[i0:i1]], "inst": [inst[i0:i1]], "moving": [moving[i0:i1]],
                 "beam": [rows], "weight": [weight], "offset": [zeros], "tau": [ones]}
        if k and n_edge:
            share = np.float32(1.0 / (k + 1))
            # probe: the sub-ray towards each neighbour that differs
            pb, pw = np.empty(4 * n_edge, np.int64), np.empty(4 * n_edge, np.int64)
            n_probe = probe_pairs(edge, side, model.probes, pb, pw)
            pb, pw = pb[:n_probe], pw[:n_probe]
            po, pd = _subray_rays(o_w, d_world, pb, pw, model.pattern)
            # a probe that lands on its centre's own triangle, with nothing its neighbour sees in front of
            # it, sees the centre's surface: not cast; if another probe splits the beam, it is one of the
            # beam's other sub-rays (split_beams lists it with them)
            on = np.empty(n_probe, bool)
            if probes_on_centre(pb, pw, edge, side, model.probes, o_w, d_world, po, pd, dist, face,
                                scanner.face_lookup.corners, lo_r, hi_r, SPLIT_STEP_M, SPLIT_STEP_REL, L, on):
                n_probe = drop_on_centre(on, pb, pw, po, pd)
                pb, pw, po, pd = pb[:n_probe], pw[:n_probe], po[:n_probe], pd[:n_probe]
            probe = _cast_subrays(scanner, plan, cols, aimed, po, pd, pb, i0, n_in, hi_r)
            keep, split = np.empty(n_probe, bool), np.empty(n_probe, np.int64)
            rb, rw = np.empty(n_probe * k, np.int64), np.empty(n_probe * k, np.int64)
            n_split, n_rest = split_beams(pb, pw, dist, face, inst, probe["dist"],
                                          np.ascontiguousarray(probe["face"], np.int32), probe["inst"],
                                          scanner.face_lookup.label, np.float32(lo_r), np.float32(hi_r),
                                          np.float32(SPLIT_STEP_M), np.float32(SPLIT_STEP_REL), k, keep, split, rb, rw)
            split, rb, rw = split[:n_split], rb[:n_rest], rw[:n_rest]
            if n_split:
                weight[split - i0] = share
                kept = np.flatnonzero(keep)  # the split beams' probes are kept
                sub = {key: v.take(kept, axis=0) for key, v in probe.items()}
                if p.edge_subrays == "all":  # with their other sub-rays
                    ro, rd = _subray_rays(o_w, d_world, rb, rw, model.pattern)
                    rest = _cast_subrays(scanner, plan, cols, aimed, ro, rd, rb, i0, n_in, hi_r)
                    sub = {key: np.concatenate([v, rest[key]]) for key, v in sub.items()}
                else:  # towards a neighbour that sees the centre's surface, a sub-ray sees it too
                    weight += share * np.bincount(rb - i0, minlength=n_in).astype(np.float32)
                for key, v in sub.items():
                    parts[key].append(v)
                m = len(sub["beam"])
                parts["weight"].append(np.full(m, share, np.float32))
                parts["offset"].append(np.zeros(m, np.float32))
                parts["tau"].append(np.ones(m, np.float32))
        _behind_glass(scanner, plan, cols, aimed, parts, scanner.face_lookup, p.glass_layers, hi_r, n_in)
        cat = {key: np.concatenate(v) if len(v) > 1 else v[0] for key, v in parts.items() if key not in ("o", "dw")}
        per_beam = 2 if p.mode == "dual" else 1
        buf = np.empty(per_beam * n_in, POINT_DTYPE)
        got = beam_returns(buf, n_in, cols.start * L, cat["beam"], cat["weight"], cat["offset"], cat["tau"],
                           cat["dist"], np.ascontiguousarray(cat["face"], np.int32),
                           np.ascontiguousarray(cat["df"], np.float32), cat["inst"], cat["moving"],
                           tables._o, tables._d, tables._azimuth, tables._column_time, tables._ring, tables._laser,
                           faces, opt.reflectivity, opt.lobe_gain, opt.lobe_exponent, opt.reference_range_m,
                           opt.min_range_m, sweep.alpha, p.detection_threshold, p.separation_m, p.mode == "dual",
                           lo_r, hi_r, sweep.key, model.ring_sigma, sweep.skew, model.k_inc)
    except BaseException:
        sweep.fail(i)
        raise
    sweep.deliver(i, buf, got)


class FaceLookup:
    """Per face-table row what the glass pass reads, gathered once per scanner.

    Attributes
    ----------
    glass : (F + 1,) bool
        The beam goes on behind the face: its material lets light through, has no room behind it
        (``Optics.room``) and its class closes no cabin (``Optics.cabin``); the last entry (for face
        -1, no hit) is False.
    transmittance : (F + 1,) float32
        One-way transmittance of the face's material.
    label : (F + 1,) int64
        ``class << 16 | instance`` of the face (-1 in the last entry).
    interior : (C,) bool
        Per class id: its cabin is modelled (``Optics.interior``).
    corners : (F_town, 3, 3) float32
        The town's triangles as cast (``caster.triangle_corners()``; rows from ``F_town`` on are actors').
    """

    def __init__(self, faces: np.ndarray, optics, corners: np.ndarray):
        mat = faces["material"]
        self.transmittance = np.append(optics.transmittance[mat], np.float32(0.0)).astype(np.float32)
        ends = optics.room[mat] | optics.cabin[faces["class"]]
        self.glass = (self.transmittance > 0) & ~np.append(ends, False)
        self.label = np.append((faces["class"].astype(np.int64) << 16) | faces["instance"], -1).astype(np.int64)
        self.interior = np.ascontiguousarray(optics.interior, bool)
        self.corners = corners


def _behind_glass(scanner, plan, cols, aimed, parts, lookup, layers, max_range, n_in) -> None:
    """Append to ``parts`` the rays continued behind every pane their ray list hits (``layers`` deep)."""
    r_max, step_m = np.float32(max_range), np.float32(GLASS_STEP_M)
    src = [{key: v[i] for key, v in parts.items()} for i in range(len(parts["face"]))]
    for _ in range(layers):
        picked = []
        for part in src:  # the rows that end on glass, continued behind it (part by part: no copy of the rest)
            n = len(part["face"])
            rows, o = np.empty(n, np.int64), np.empty((n, 3), np.float32)
            off, tau, left = np.empty(n, np.float32), np.empty(n, np.float32), np.empty(n, np.float32)
            pane = np.empty(n, np.int64)
            m = pane_rays(part["face"], part["dist"], part["offset"], part["tau"], part["inst"], part["o"], part["dw"],
                          lookup.glass, lookup.transmittance, lookup.label, r_max, step_m, rows, o, off, tau, left,
                          pane)
            if m:
                rows = rows[:m]
                picked.append((o[:m], part["dw"][rows], off[:m], tau[:m], left[:m], pane[:m], part["beam"][rows],
                               part["weight"][rows]))
        if not picked:
            return
        o, dw, offset, tau, left, pane, beam, weight = (np.concatenate(c) if len(picked) > 1 else c[0]
                                                        for c in zip(*picked, strict=True))
        d = dw.copy()
        dist, face = scanner.caster.intersect_local(o, d, left, mark_misses=False)
        order = np.argsort(beam, kind="stable")  # the actors want each beam's rays together
        ptr = np.zeros(n_in + 1, np.int64)
        ptr[1:] = np.bincount(beam, minlength=n_in)
        rows = (np.cumsum(ptr), order.astype(np.int64))
        inst, moving = _actor_hits(scanner, plan, cols, o, d, dist, face, aimed, rows=rows, offset=offset)
        # the interior of the object whose glass the ray crossed is not modelled: absorbed there
        face = np.ascontiguousarray(face, np.int32)
        absorb_interior(face, inst, pane, lookup.label, lookup.transmittance, lookup.interior)
        layer = {"o": o, "dw": dw, "df": d, "dist": dist, "face": face, "inst": inst, "moving": moving, "beam": beam,
                 "weight": weight, "offset": offset, "tau": tau}
        for key, v in layer.items():
            parts[key].append(v)
        src = [layer]
