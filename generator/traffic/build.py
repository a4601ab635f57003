"""Build the world in time: the static town + simulated vehicles, pedestrians and the ego.

:func:`build_world` is the one entry point. With every ``traffic`` density 0 it returns the
frozen town (no actors, the ego at constant speed along route 0, exactly as before traffic
existed). Otherwise pedestrians are simulated first (they only obey the signals), then the
vehicles and the ego, which also keep off crosswalks pedestrians are on. Every draw comes from
a stream named ``("traffic", ...)`` of the spec seed, and the simulation is causal, so the
world at a time ``t`` does not depend on how long a run is.

Vehicles start on free lane edges at rest and settle for :data:`WARMUP_S` seconds (the ego
waiting at its start) before t = 0. The traffic drives in the town it is given
(:class:`~generator.layout.town.Town`): its grid, and its asset library, so moving vehicles and
people are the static town's models -- in a re-drawn town the shared library of the spec's seed.
"""

from __future__ import annotations

import logging
import time

import numpy as np

from generator.errors import SpecError
from generator.geometry.proxy import label_proxy
from generator.layout.network.cycles import route_node_cycles
from generator.layout.network.design_vehicle import EGO_SIZE_M
from generator.layout.network.measures import ARM_DIRS, CROSSWALK_U
from generator.layout.placement.appearance import fleet_paint
from generator.layout.town import Town
from generator.rng import stream
from generator.traffic.lanes.clearance import MARGIN_M, blocked_lanes, too_narrow
from generator.traffic.lanes.graph import LaneGraph
from generator.traffic.lanes.roundabouts import GIVE_WAY_CLEAR_S
from generator.traffic.lanes.signals import CLEAR_S, Signals
from generator.traffic.mapped_tracks import map_track
from generator.traffic.movers import DT_S, Mover
from generator.traffic.pedestrians.gait import walker_gait
from generator.traffic.pedestrians.simulate import simulate_pedestrians
from generator.traffic.vehicles.fleet import KINDS, drives, fleet_proto, how_many, n_variants, widest_half_width
from generator.traffic.vehicles.sim import Vehicle, VehicleSim, arm_towards, recorded_poses
from generator.world.actors import Actor, Track, TrackTrajectory, World, frozen_world
from generator.world.trajectory import EgoTrajectory

log = logging.getLogger(__name__)

WARMUP_S = 20.0
LEAD_IN = 2           #: track samples before t = 0 (central differences at t = 0 see real motion)
LOOKAHEAD_S = CLEAR_S + 1.0  #: vehicles ask about crosswalks up to CLEAR_S ahead (VehicleSim._maybe_grant)
#: ... and up to GIVE_WAY_CLEAR_S ahead at a roundabout: a town with roundabouts simulates its people that much
#: further at once instead of finding out after a whole drive and simulating everything again
GIVE_WAY_LOOKAHEAD_S = max(CLEAR_S, GIVE_WAY_CLEAR_S) + 1.0
MAX_DRIVE_S = 900.0
SPACING_M = 6.0       #: lanes hold at most one vehicle per (length + this), for the capacity check


def build_world(spec, scene: Town, duration_s: float, distance_m: float = 0.0) -> World:
    """The world of ``spec`` over at least ``[0, duration_s]`` seconds.

    Parameters
    ----------
    spec : generator.spec.SceneSpec
    scene : Town
        The static town built from ``spec`` (:func:`generator.layout.build_scene`): the traffic drives
        on its grid and draws its vehicles and people from its asset library (a frozen town, with
        every ``traffic`` density 0, may be any :class:`~generator.world.scene.SceneModel`).
    duration_s : float
        Simulated seconds from t = 0 (tracks run a little longer for central differences).
    distance_m : float
        Keep simulating until the ego has driven this far as well (frames along the route).

    Raises
    ------
    SpecError
        More vehicles than the free lanes can hold, or the ego cannot drive ``distance_m``
        within :data:`MAX_DRIVE_S`.
    TypeError
        Traffic asked for in a scene that is not a :class:`Town`.
    """
    if not spec.traffic.enabled:
        return frozen_world(scene, EgoTrajectory(scene.paths[0], spec.paths.speed_mps))
    if not isinstance(scene, Town):
        raise TypeError(f"build_world needs the Town build_scene returns, got {type(scene).__name__}")
    world_scene, tmap, grid, lib = scene, scene.town_map, scene.grid, scene.library
    if tmap is not None:    # streets crossing at an angle: the traffic runs on the town's grid
        scene = scene.layout
    t_start = time.perf_counter()
    graph = LaneGraph(grid)
    signals = Signals(spec.seed, grid.nodes, grid.roundabouts)
    half_width, widest = widest_half_width(spec, lib, KINDS, EGO_SIZE_M[1])
    log.debug("lanes kept clear of static objects to %.2f m from their centre lines (%s)", half_width + MARGIN_M,
              widest)
    lookahead_s = GIVE_WAY_LOOKAHEAD_S if grid.roundabouts else LOOKAHEAD_S
    horizon_s = duration_s + 1.0 + lookahead_s
    if distance_m > 0:  # the drive may take longer than asked: cover a slow ego
        horizon_s = max(horizon_s, distance_m / (0.25 * spec.paths.speed_mps) + 5.0 + lookahead_s)
    network: dict = {}      # the walk network does not depend on the horizon: built once
    while True:  # vehicles look ahead at crosswalks: pedestrians must be simulated past the drive's end
        peds = _pedestrians(spec, grid, scene, signals, lib, int(np.ceil(horizon_s / DT_S)) + 1, network)
        crossing = _crosswalk_occupancy(grid, graph, peds)
        blocked = blocked_lanes(graph, scene, half_width)
        movers, ego_track, ego_dist = _drive(spec, graph, scene, signals, lib, blocked, crossing, duration_s,
                                             distance_m, None if tmap is None else tmap.A)
        if crossing is None or crossing.asked_s <= horizon_s:
            break
        horizon_s = 2.0 * crossing.asked_s  # same answers up to the old horizon (causal): a longer run, same world
        graph = _fresh_graph(grid, graph)
    peds = [_lead_in(_extend_track(p, len(ego_dist)), grid.ground_height if p.attrs.get("role") == "walking" else None)
            for p in peds]
    if tmap is not None:
        for m in movers + peds:
            m.track = map_track(m.track, tmap, (m.proto.lo[:2] + m.proto.hi[:2]) / 2)
        ego_track = map_track(ego_track, tmap)      # ego_dist is measured in the world already (_drive)
    world = _assemble(world_scene, movers + peds, TrackTrajectory(ego_track, ego_dist), ego_track.t1)
    log.info("traffic %s: %d vehicles, %d pedestrians over %.1f s, simulated in %.2f s", spec.name, len(movers),
             len(peds), ego_track.t1, time.perf_counter() - t_start)
    return world


def _pedestrians(spec, grid, scene, signals, lib, n_steps: int, network: dict | None = None) -> list[Mover]:
    if not (drives(spec.traffic, "pedestrians_per_100m") or drives(spec.traffic, "standing_pedestrians_per_100m")):
        return []
    return simulate_pedestrians(spec, grid, scene, signals, lib, n_steps, DT_S, network)


#: answers of :attr:`LaneGraph.memo` that hang on the lanes' and connectors' paths and the scene
#: only, not on the pruning a drive does: a new graph of the same grid may keep them
_GEOMETRY_MEMOS = ("blocked_lanes", "_blocked_turn_memo", "_swept_poses", "_crosswalk_sweep")


def _fresh_graph(grid, old: LaneGraph) -> LaneGraph:
    """A new lane graph of ``grid`` (the drive prunes the old one's successors) that keeps the old
    one's answers about blocked lanes and turns (the same paths: the graph is built deterministically)."""
    graph = LaneGraph(grid)
    graph.memo.update({k: v for k, v in old.memo.items() if (k[0] if isinstance(k, tuple) else k) in _GEOMETRY_MEMOS})
    return graph


def _lead_in(m: Mover, ground=None) -> Mover:
    """Prepend :data:`LEAD_IN` samples before t = 0 at the first step's horizontal velocity, so
    central differences at t = 0 see the motion (a walker already walking) instead of a clamped
    track. Their height is ``ground(xy)`` ((n, 2) -> (n,) metres: a walker's feet on the ground
    there, :func:`generator.traffic.pedestrians.simulate.feet_height`), or the first sample's without it;
    extrapolating a step up the kerb would sink the feet below the road."""
    tr = m.track
    if tr.t0 <= -LEAD_IN * DT_S + 1e-12 or len(tr.yaw) < 2:
        return m
    step = tr.xyz[1] - tr.xyz[0]
    back = tr.xyz[0] - step * np.arange(LEAD_IN, 0, -1)[:, None]
    back[:, 2] = tr.xyz[0, 2] if ground is None else ground(back[:, :2])
    m.track = Track(tr.t0 - LEAD_IN * DT_S, tr.dt, np.vstack([back, tr.xyz]),
                    np.r_[np.repeat(tr.yaw[:1], LEAD_IN), tr.yaw])
    return m


def _extend_track(m: Mover, n: int) -> Mover:
    tr = m.track
    if len(tr.yaw) >= n:
        return m
    pad = n - len(tr.yaw)
    m.track = Track(tr.t0, tr.dt, np.vstack([tr.xyz, np.repeat(tr.xyz[-1:], pad, 0)]),
                    np.r_[tr.yaw, np.repeat(tr.yaw[-1:], pad)])
    return m


def _crosswalk_occupancy(grid, graph: LaneGraph, peds: list[Mover]):
    """``crossing(node, arm, t0, t1)``: is a pedestrian within 1 m of that crosswalk band then."""
    walkers = [p for p in peds if p.attrs.get("role") != "standing"]
    if not walkers:
        return None
    xy = np.stack([p.track.xyz[:, :2] for p in walkers], 1)   # (T, n, 2)
    occupied = {}
    for node in grid.nodes:
        c = grid.node_xy(node)
        for arm in grid.arms(node):
            e = ARM_DIRS[arm]
            rel = xy - c
            along = rel @ e
            across = rel @ np.array([-e[1], e[0]])
            u0, u1 = grid.road_half + CROSSWALK_U[0] - 1.0, grid.road_half + CROSSWALK_U[1] + 1.0
            inside = (along > u0) & (along < u1) & (np.abs(across) < grid.road_half + 0.5)
            occupied[(node, arm)] = inside.any(1)

    def crossing(node, arm, t0: float, t1: float) -> bool:
        crossing.asked_s = max(crossing.asked_s, t1)
        occ = occupied[(node, arm)]
        i0 = max(0, int(np.floor(t0 / DT_S)))      # before t = 0 (the warm-up) people are where they start
        i1 = max(i0 + 1, int(np.ceil(t1 / DT_S)) + 1)
        return bool(occ[i0:i1].any())

    crossing.asked_s = 0.0  # the latest instant asked about: the run is redone if it lies past the simulated one

    return crossing


def _prune(graph: LaneGraph, blocked: set[int], keep: set[int]) -> set[int]:
    """Drop blocked lanes from the graph, and then every lane left without a way on (dead ends).

    Lanes in ``keep`` (the ego's route, clear of objects by construction) are never dropped.
    Returns every dropped lane edge.
    """
    blocked = set(blocked) - keep
    while True:
        for e in graph.edges:
            if e.kind == "lane":
                e.succ = [c for c in e.succ if graph.edges[c].succ[0] not in blocked]
        dead = {e.index for e in graph.lanes() if not e.succ and e.index not in blocked and e.index not in keep}
        if not dead:
            return blocked
        blocked |= dead


def _ego_route(graph: LaneGraph) -> list[int]:
    """Route 0 (the comb loop of :mod:`generator.layout.network.routes`) as a cycle of edges of ``graph``."""
    grid = graph.grid
    nodes = route_node_cycles(len(grid.xs) - 1, len(grid.ys) - 1)[0]
    k = grid.lanes - 1
    out = []
    for i, a in enumerate(nodes):
        b, c = nodes[(i + 1) % len(nodes)], nodes[(i + 2) % len(nodes)]
        out.append(graph.lane_out(a, arm_towards(a, b), k).index)
        out.append(graph.connector[(b, arm_towards(b, a), arm_towards(b, c), k)])
    return out


def _drive(spec, graph, scene, signals, lib, blocked, crossing, duration_s, distance_m, to_world=None):
    """Simulate the vehicles and the ego; the ego's driven distance is measured in the world
    (``to_world``: the (2, 2) map of a skewed town, None for the grid itself)."""
    tr = spec.traffic
    route = _ego_route(graph)
    blocked = _prune(graph, blocked, set(route))
    free = [e for e in graph.lanes() if e.index not in blocked]
    if not free:
        raise SpecError(spec.source, "traffic", "every lane is blocked by parked objects: no room for moving traffic")
    ego = Vehicle(0, *EGO_SIZE_M, spec.paths.speed_mps, 1.5, [route[0]], 0.0, stream(spec.seed, "traffic", "ego"),
                  ego_route=route, stop_p=tr.ego_stop_probability)
    ego.plan.append(route[1])
    ego.route_pos = 1
    vehicles, movers = [ego], []
    km = sum(e.length for e in free) / 1000.0
    _check_capacity(spec)
    g = stream(spec.seed, "traffic", "vehicles")
    paint = stream(spec.seed, "traffic", "vehicles", "paint")   # colours never move a vehicle
    taken: dict[int, list] = {route[0]: [(0.0, EGO_SIZE_M[0])]}
    for field_name, (kind, n_var, speed, a_max, _) in KINDS.items():
        for _ in range(how_many(tr, field_name, km)):
            proto = fleet_proto(lib, kind, int(g.integers(n_variants(lib, kind, n_var))))
            length, width = float(proto.hi[0] - proto.lo[0]), float(proto.hi[1] - proto.lo[1])
            avoid = frozenset(too_narrow(graph, scene, width / 2, set(route), length))
            e, s = _free_spot(graph, [f for f in free if f.index not in avoid] if avoid else free, taken, length, g,
                              field_name, spec)
            i = len(vehicles)
            v = Vehicle(i, length, width, min(tr.speed_limit_mps * float(g.uniform(*speed)), tr.speed_limit_mps),
                        a_max, [e.index], s, stream(spec.seed, "traffic", "vehicle", i), avoid=avoid)
            vehicles.append(v)
            # still take the values the old per-vehicle colour took, so a seed's traffic drives as before
            # (other draw orders put a turning bus onto a car at t = 0, tests/test_traffic.py)
            g.integers(8), g.uniform(0.9, 1.1, 3)
            movers.append(Mover(kind, lib.main_class(kind), proto, None, {**fleet_paint(paint), "role": "driving"}))
    sim = VehicleSim(graph, signals, vehicles, crossing)
    for v in vehicles:
        sim._extend(v)
    ego.v_des = 0.0
    n_warm = round(WARMUP_S / DT_S)
    at = []   # (edge, s) of every vehicle at every recorded step: the poses are read after the run
    for k in range(n_warm):
        if k >= n_warm - LEAD_IN:   # the warm-up's last LEAD_IN samples: tracks start before t = 0
            at.append([(v.edge, v.s) for v in vehicles])
        sim.step(-WARMUP_S + k * DT_S, DT_S)
    ego.v_des = spec.paths.speed_mps
    ego_xy, dist = [], [0.0]
    t, k = 0.0, 0
    while True:
        at.append([(v.edge, v.s) for v in vehicles])
        ego_xy.append(sim.pose(ego)[0])
        if k > 0:
            step = ego_xy[-1] - ego_xy[-2]
            dist.append(dist[-1] + float(np.linalg.norm(step if to_world is None else to_world @ step)))
        if t >= duration_s + 1.0 and dist[-1] >= distance_m + 1.0:
            break
        if t > MAX_DRIVE_S:
            raise SpecError(spec.source, "paths.spacing_m", f"the ego cannot drive {distance_m:.0f} m within "
                            f"{MAX_DRIVE_S:.0f} s of traffic; ask for fewer frames or less traffic")
        sim.step(t, DT_S)
        k += 1
        t = k * DT_S
    xy, hd = recorded_poses(graph, at)
    hd = np.unwrap(hd, axis=0)
    for j, m in enumerate(movers, start=1):
        c = (m.proto.lo + m.proto.hi) / 2
        cs, sn = np.cos(hd[:, j]), np.sin(hd[:, j])
        origin = xy[:, j] - np.stack([c[0] * cs - c[1] * sn, c[0] * sn + c[1] * cs], -1)
        m.track = Track(-LEAD_IN * DT_S, DT_S, np.c_[origin, np.zeros(len(origin))], hd[:, j])
    xy, hd = xy[LEAD_IN:], hd[LEAD_IN:]  # the ego's drive starts at t = 0 (it waits through the warm-up)
    ego_track = Track(0.0, DT_S, np.c_[xy[:, 0], np.zeros(len(xy))], hd[:, 0])
    return movers, ego_track, np.asarray(dist)


def _check_capacity(spec) -> None:
    tr = spec.traffic
    need = {f: getattr(tr, f) * (k[4] + SPACING_M) for f, k in KINDS.items()}   # metres of lane per km
    used = sum(need.values())
    if used > 1000.0:
        worst = max(need, key=need.get)
        raise SpecError(spec.source, f"traffic.{worst}", f"the vehicles asked for need {used / 1000:.2f} km of "
                        "lane per km of lane (all kinds together, with safe gaps); lower the densities")


def _free_spot(graph, free, taken, length, g, field_name, spec):
    if not free:  # every lane too narrow for this vehicle between the parked objects
        raise SpecError(spec.source, f"traffic.{field_name}",
                        "no lane of the town is wide enough for this vehicle beside the parked objects; "
                        "set it to 0 or widen the lanes")
    lengths = np.array([e.length for e in free])
    for _ in range(200):
        e = free[int(g.choice(len(free), p=lengths / lengths.sum()))]
        lo, hi = length / 2 + 1.0, e.length - graph.stop_s_from_end - length / 2 - 1.0
        if hi <= lo:
            continue
        s = float(g.uniform(lo, hi))
        if all(abs(s - s2) > (length + l2) / 2 + SPACING_M for s2, l2 in taken.get(e.index, [])):
            taken.setdefault(e.index, []).append((s, length))
            return e, s
    raise SpecError(spec.source, f"traffic.{field_name}", "more vehicles than the free lanes can hold; lower it")


def _assemble(scene, movers: list[Mover], ego: TrackTrajectory, duration_s: float) -> World:
    base = max([o.instance_id for o in scene.objects] + [0]) + 1
    if base + len(movers) > 65535:
        raise SpecError("", "traffic", f"{len(movers)} actors exceed the instance ids left in a uint16 label")
    prototypes, proxies, actors, cycles = {}, {}, [], {}
    for uid, m in enumerate(movers):
        key = f"actor_{m.proto.key}"
        if key not in prototypes:
            prototypes[key] = m.proto.mesh
            hull = label_proxy(m.proto.mesh)
            if hull is not None:
                proxies[key] = hull
        lo, hi = np.asarray(m.proto.lo, float), np.asarray(m.proto.hi, float)
        gait = walker_gait(key, m.proto.mesh, m.track, prototypes, cycles) if m.attrs.get("role") == "walking" else None
        if gait is not None:
            lo, hi = gait.lo.min(0), gait.hi.max(0)             # the box of every phase
        actors.append(Actor(uid, f"actor_{m.kind}_{uid:04d}", m.kind, m.cls, base + uid, key, tuple(hi - lo),
                            tuple((lo + hi) / 2), m.track, key if key in proxies else None, dict(m.attrs), gait))
    return World(scene, actors, prototypes, proxies, ego, duration_s)

