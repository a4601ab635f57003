"""Pedestrians: people walking the sidewalks and crossing at crosswalks, and people standing.

:func:`simulate_pedestrians` builds the walk network of the town
(:mod:`generator.traffic.pedestrians.walkways`), puts ``traffic.pedestrians_per_100m`` walkers on it and
walks them (:mod:`generator.traffic.pedestrians.sim`), and places
``traffic.standing_pedestrians_per_100m`` people standing on the pavement clear of the
walking lines and of every static object (and, on shared streets, beside the lanes on the
carriageway: :mod:`generator.traffic.pedestrians.shared`). Prototypes are the layout's own person variants
(:func:`person_protos`, as :func:`generator.layout.placement.street.place_people` makes
them): walking poses for walkers, standing poses for standers.

Randomness: walker ``k`` draws its prototype, clothing, pace and start from
``("traffic", "pedestrian", k)`` and its turns from ``("traffic", "pedestrian", k, "route")``;
stander ``k`` from ``("traffic", "pedestrian", "standing", k)``. Same spec, same tracks.
"""

from __future__ import annotations

import logging
import time

import numpy as np
from scipy.spatial import cKDTree

from generator.geometry.boxes import box_pairs_overlap
from generator.layout.network.design_vehicle import EGO_SIZE_M
from generator.layout.network.grid import Grid
from generator.layout.placement.appearance import outfit
from generator.layout.placement.prototypes import Library, Proto
from generator.layout.placement.variety import person_variants
from generator.rng import stream
from generator.spec.model import SceneSpec
from generator.traffic.movers import DT_S, Mover
from generator.traffic.pedestrians import clear as wc
from generator.traffic.pedestrians import net as wn
from generator.traffic.pedestrians import sim as ws
from generator.traffic.pedestrians import zones as wz
from generator.traffic.pedestrians.lines import R_TURN
from generator.traffic.pedestrians.shared import shared_standers
from generator.traffic.pedestrians.walkways import Walkways, build_walkways, obstacles_of
from generator.traffic.vehicles.fleet import KINDS, how_many, widest_half_width
from generator.world.actors import Track

log = logging.getLogger(__name__)

SPEED_JITTER = 0.2   #: each walker's pace is the spec's pace times U(1 - j, 1 + j)
MARGIN_M = 0.05      #: clearance added round every footprint
WARMUP_S = 10.0      #: walked before t = 0 so the sequence opens mid-stride, not with everyone starting
SPAWN_TRIES = 200


def person_protos(lib: Library, spec: SceneSpec) -> tuple[list[Proto], list[Proto]]:
    """(standing, walking) person prototypes, the same variants the static town uses."""
    protos = person_variants(lib, spec)
    return protos[:len(protos) // 2], protos[len(protos) // 2:]


def sidewalk_length(grid: Grid) -> float:
    """Metres of sidewalk the densities count: both sides of every street segment."""
    return 2.0 * sum(seg.length for seg in grid.segments)


def max_speed(spec: SceneSpec) -> float:
    """The fastest a walker ever goes (its pace at most, hurrying across a street), m/s."""
    return wn.HURRY * (1 + SPEED_JITTER) * spec.traffic.pedestrian_speed_mps


def simulate_pedestrians(spec: SceneSpec, grid: Grid, scene, signals, lib: Library, n_steps: int,
                         dt: float = DT_S, network: dict | None = None) -> list[Mover]:
    """Walking and standing pedestrians of the town for ``n_steps`` samples from t = 0.

    Parameters
    ----------
    spec : SceneSpec
        Densities and pace from ``spec.traffic``, heights from ``spec.heights``, the seed.
    grid : Grid
        The street grid of ``scene``.
    scene : SceneModel
        The static town: walkers and standers keep clear of its non-ground objects.
    signals : generator.traffic.lanes.signals.Signals
        Walk phases: a walker steps onto a crosswalk only when ``signals.may_cross`` allows.
    lib : Library
        Prototype library (the layout's, so walkers share the static town's person meshes).
    n_steps : int
        Samples per track; track ``k`` is at t = k * dt seconds.
    dt : float
        Sample spacing, seconds.
    network : dict, optional
        Keeps the obstacles and the walk network between calls for the same town (a longer run of
        :func:`generator.traffic.build.build_world` asks again with more steps; they do not depend on them).

    Returns
    -------
    list of Mover
        Walkers (``attrs["role"] == "walking"``) then standers (``"standing"``); empty when both
        densities are 0.
    """
    tr = spec.traffic
    length = sidewalk_length(grid)
    n_walk = how_many(tr, "pedestrians_per_100m", length / 100.0)
    n_stand = how_many(tr, "standing_pedestrians_per_100m", length / 100.0)
    if n_walk == 0 and n_stand == 0:
        return []
    t0 = time.perf_counter()
    standing, walking = person_protos(lib, spec)
    body = wc.body_of(walking + standing, MARGIN_M)
    if network is None or "walkways" not in network:
        obstacles = obstacles_of(grid, scene, body)
        network = {} if network is None else network
        network.update(obstacles=obstacles, walkways=build_walkways(grid, obstacles, body))
    obstacles, ww = network["obstacles"], network["walkways"]
    t1 = time.perf_counter()
    cls = lib.main_class("person")
    movers = _walkers(spec, grid, ww, body, signals, walking, n_walk, n_steps, dt, cls) if n_walk and ww.paths else []
    t2 = time.perf_counter()
    movers += _standers(spec, grid, ww, body, obstacles, standing, n_stand, n_steps, dt, cls)
    widest, _ = widest_half_width(spec, lib, KINDS, EGO_SIZE_M[1])
    movers += shared_standers(spec, grid, obstacles, standing, n_steps, dt, cls, _proto_box, widest)   # shared streets
    log.info("pedestrians: %d walking, %d standing, %d steps (network %.2f s, walking %.2f s, standing %.2f s)",
             sum(m.attrs["role"] == "walking" for m in movers), sum(m.attrs["role"] == "standing" for m in movers),
             n_steps, t1 - t0, t2 - t1, time.perf_counter() - t2)
    return movers


def _walkers(spec, grid: Grid, ww: Walkways, body: wc.Body, signals, protos, n: int, n_steps: int, dt: float,
             cls: str):
    length = np.array([p.s[-1] for p in ww.paths])
    gap = wz.follow_gap(body, R_TURN)
    zones = wz.conflict_zones(ww.paths, ww.succ, wz.reach(ww.succ, length, wn.FOLLOW_M), body, gap)
    net = wn.Net(ww, zones, gap)
    n_warm = round(WARMUP_S / dt)
    n_decide = int((n_warm + n_steps) * dt * max_speed(spec) / max(length.min(), 0.5)) + ws.K_ROUTE + 8
    free = _spawn_mask(ww, zones, body, gap)
    weights = np.array([f.sum() for f in free], np.float64)
    edges, ss, xy, pace, decide, drawn = [], [], [], [], [], []
    for k in range(n):
        g = stream(spec.seed, "traffic", "pedestrian", k)
        proto, look = protos[int(g.integers(len(protos)))], outfit(g)
        v = spec.traffic.pedestrian_speed_mps * g.uniform(1 - SPEED_JITTER, 1 + SPEED_JITTER)
        spot = _spawn(g, ww, free, weights, np.array(xy).reshape(-1, 2), gap + 0.3)
        if spot is None:
            log.warning("no room for walker %d of %d on the walk network; placed %d", k + 1, n, len(edges))
            break
        edges.append(spot[0])
        ss.append(spot[1])
        xy.append(ww.paths[spot[0]].points[round(spot[1] / ww.paths[spot[0]].s[1]), :2])
        pace.append(v)
        decide.append(stream(spec.seed, "traffic", "pedestrian", k, "route").random(n_decide))
        drawn.append((proto, look))
    if not edges:
        return []
    t0 = time.perf_counter()
    pos, yaw = ws.simulate(net, signals, np.array(edges), np.array(ss), np.array(pace), np.array(decide),
                           n_warm, n_steps, dt)
    pos[..., 2] = feet_height(grid, pos[..., :2])
    log.debug("%d walkers, %d + %d steps: %.2f s", len(edges), n_warm, n_steps, time.perf_counter() - t0)
    return [Mover("person", cls, proto, Track(0.0, dt, pos[k], yaw[k]), {**look, "role": "walking"})
            for k, (proto, look) in enumerate(drawn)]


def feet_height(grid: Grid, xy: np.ndarray) -> np.ndarray:
    """Height of a walker's feet at centres ``xy``: the ground under the centre, exactly.

    Parameters
    ----------
    grid : Grid
    xy : (..., 2) float64
        Walker centres, world frame, metres.

    Returns
    -------
    (...) float64
        :meth:`Grid.ground_height` there, metres: kerb height on the pavement (a closed street's
        park, caps and corners included), 0 on the road (where walkers only cross). A walker
        steps up or down the kerb between two samples; interpolating the positions of the walk
        network instead would leave it half-way, inside the kerb, for a sample.
    """
    xy = np.asarray(xy, np.float64)
    return grid.ground_height(xy.reshape(-1, 2)).reshape(xy.shape[:-1])


def _spawn_mask(ww: Walkways, zones: wz.Zones, body: wc.Body, gap: float) -> list[np.ndarray]:
    """Per edge: (n,) bool, samples where a walker may start (off the road and the curb, outside
    every conflict interval, not between a curb stop and the road)."""
    out = []
    for e, p in enumerate(ww.paths):
        ok = np.ones(len(p.s), bool)
        for j in np.flatnonzero(zones.edge == e):
            ok &= (p.s < zones.s0[j] - gap) | (p.s > zones.s1[j] + 0.1)
        if ww.node[e] is not None:
            ok &= (p.s < ww.stop_s[e] - gap) | (p.s > ww.road_s[e, 1] + body.hx + 0.5)
        for f in ww.succ[e]:
            if ww.node[f] is not None and ww.stop_s[f] < gap:
                ok &= p.s < p.s[-1] + ww.stop_s[f] - gap
        out.append(ok)
    return out


def _spawn(g: np.random.Generator, ww: Walkways, free, weights: np.ndarray, taken: np.ndarray, clear: float):
    """(edge, arc length) of a free start at least ``clear`` metres from every ``taken`` (k, 2) point."""
    if weights.sum() <= 0:
        return None
    tree = cKDTree(taken) if len(taken) else None
    for _ in range(SPAWN_TRIES):
        e = int(g.choice(len(weights), p=weights / weights.sum()))
        i = int(g.choice(np.flatnonzero(free[e])))
        p = ww.paths[e].points[i, :2]
        if tree is None or not tree.query_ball_point(p, clear):
            return e, float(ww.paths[e].s[i])
    return None


def _standers(spec, grid: Grid, ww: Walkways, body: wc.Body, obstacles: wc.Obstacles, protos, n: int,
              n_steps: int, dt: float, cls: str) -> list[Mover]:
    """People standing on the sidewalks, clear of the walking lines, the static objects and each other."""
    if n == 0:
        return []
    lanes = np.concatenate([p.points[::2, :2] for p in ww.paths]) if ww.paths else np.zeros((0, 2))
    heads = np.concatenate([p.headings[::2] for p in ww.paths]) if ww.paths else np.zeros(0)
    lane_boxes = body.boxes(lanes, heads, grid.curb_h)
    lane_tree = cKDTree(lanes) if len(lanes) else None
    segs = grid.segments
    w = np.array([max(s.length - 2 * (grid.corridor_half - grid.road_half) - 1.0, 0.0) for s in segs])
    placed, out = np.zeros((0, 7)), []
    lo_v, hi_v = grid.walk_inner + 0.35, grid.corridor_half - 0.35
    for k in range(n):
        g = stream(spec.seed, "traffic", "pedestrian", "standing", k)
        proto, look = protos[int(g.integers(len(protos)))], outfit(g)
        for _ in range(SPAWN_TRIES):
            seg = segs[int(g.choice(len(segs), p=w / w.sum()))]
            u0 = grid.corridor_half - grid.road_half + 0.5
            x, y = seg.to_world(g.uniform(u0, seg.length - u0), g.choice([-1, 1]) * g.uniform(lo_v, hi_v))[0]
            yaw = float(g.uniform(-np.pi, np.pi))
            box = _proto_box(proto, x, y, grid.curb_h, yaw, MARGIN_M)
            if obstacles.hit(box).any():
                continue
            if len(placed) and box_pairs_overlap(np.repeat(box, len(placed), 0), placed).any():
                continue
            if lane_tree is not None:
                near = lane_tree.query_ball_point(box[0, :2], body.radius + np.hypot(*box[0, 2:4]))
                if near and box_pairs_overlap(np.repeat(box, len(near), 0), lane_boxes[near]).any():
                    continue
            placed = np.vstack([placed, box])
            xyz = np.repeat([[x, y, grid.curb_h]], n_steps, 0)
            out.append(Mover("person", cls, proto, Track(0.0, dt, xyz, np.full(n_steps, yaw)),
                             {**look, "role": "standing"}))
            break
        else:
            log.warning("no room for standing pedestrian %d of %d; placed %d", k + 1, n, len(out))
            break
    return out


def _proto_box(proto: Proto, x: float, y: float, z: float, yaw: float, grow: float) -> np.ndarray:
    """(1, 7) box of ``proto`` standing at (x, y, z) turned by ``yaw``, grown by ``grow`` metres."""
    c = (proto.lo + proto.hi) / 2
    cs, sn = np.cos(yaw), np.sin(yaw)
    h = (proto.hi - proto.lo) / 2 + grow
    return np.array([[x + c[0] * cs - c[1] * sn, y + c[0] * sn + c[1] * cs, h[0], h[1], yaw,
                      z + proto.lo[2], z + proto.hi[2]]])
