"""The walk network: directed walking edges along every sidewalk and across every crosswalk.

The straight lines and the turns joining them come from :mod:`generator.traffic.pedestrians.lines`.
Lines are cut into *edges* at the ends of the turns; the pieces of a line crossing a street
are the crosswalks, tagged with their node. Where a static object stands on a line
(:class:`~generator.traffic.pedestrians.clear.Obstacles`) the piece is shifted sideways (not at its
ends, on the sidewalk or inside the crosswalk band, preferably inside its own half of the
sidewalk); where no shift clears it, the edge is cut, and so is everything that no longer
leads anywhere. Edges are :class:`~generator.world.scene.Path` polylines sampled every
:data:`SAMPLE_M`. Frames: world, metres, z up: the height of the ground under the point
(:meth:`~generator.layout.network.grid.Grid.ground_height`: kerb height on the pavement, closed
streets' parks and corners included, 0 across a street; a walker steps up and down the kerb).
"""

from __future__ import annotations

import itertools
import logging
from dataclasses import dataclass

import numpy as np

from generator.layout.network.grid import Grid
from generator.layout.network.measures import CROSSWALK_U
from generator.traffic.pedestrians import clear as wc
from generator.traffic.pedestrians.lines import (
    KERB,
    R_TURN,
    Line,
    along,
    arc,
    lane_offsets,
    lines,
    street_distance,
    street_distance_bound,
    turns,
)
from generator.world.scene import Path

log = logging.getLogger(__name__)

ROW_M = 0.1         #: along-line resolution of a sideways shift
SAMPLE_M = 0.05     #: sample spacing of every edge (fine: finite differences see smooth turns)
FIX_M = 0.3         #: no sideways shift this close to the ends of an edge (where it joins others)
SIGMA_M = 0.4       #: smoothing of a sideways shift, metres
OTHER_COST = 10.0   #: cost of a lateral step into the other direction's half of the sidewalk (own half: 1)


@dataclass
class Walkways:
    """The walk network.

    Attributes
    ----------
    paths : list of Path
        Edges: ``points`` (n, 3) world metres (z on the pavement or the road), ``headings``
        (n,) radians, ``s`` (n,) arc length; uniformly sampled.
    succ : list of tuple of int
        Successor edges of each edge (every edge has at least one).
    node : list of (int, int) or None
        The intersection whose crosswalk an edge crosses (None off the road).
    road_s : (E, 2) float64
        Arc-length range of an edge on the road (NaN when it stays on the pavement), metres.
    stop_s : (E,) float64
        Where a walker waits for the signal before a crosswalk: arc length of its centre
        (may be negative: on the edge before), NaN off crosswalks.
    offsets : tuple of float
        Lateral offsets of the kerb (and lot) lines from the street centre lines, metres.
    """

    paths: list[Path]
    succ: list[tuple[int, ...]]
    node: list[tuple[int, int] | None]
    road_s: np.ndarray
    stop_s: np.ndarray
    offsets: tuple[float, ...]


def _shifted(grid: Grid, line: Line, t: np.ndarray, offs, obstacles: wc.Obstacles, body: wc.Body) -> np.ndarray | None:
    """(n, 2) points of the piece at along-coordinates ``t`` (every :data:`ROW_M`), shifted sideways
    round obstacles; None when no shift clears them.

    The shift is zero near the ends of the piece, stays on the sidewalk (inside the crosswalk
    band near a node) and prefers its own family's half of the sidewalk: where it has to
    borrow the other half, the simulation lets the two directions take turns there.
    """
    xy = line.xy(t)
    yaw = float(np.arctan2(line.u[1], line.u[0]))
    blocked = np.flatnonzero(obstacles.hit(body.boxes(xy, np.full(len(t), yaw), grid.curb_h)))
    if not len(blocked):
        return xy
    # shift only round the blocked stretch (plus room to ramp out to the far side of the sidewalk)
    ramp = int(np.ceil(2 * grid.sidewalk_w / wc.SHIFT_STEP_M))
    i0, i1 = max(0, blocked[0] - ramp), min(len(t), blocked[-1] + ramp + 1)
    inner = _shift_rows(grid, line, t[i0:i1], offs, obstacles, body, t[0], t[-1])
    if inner is None:
        return None
    out = xy.copy()
    out[i0:i1] = inner
    g = np.gradient(out, axis=0)
    return None if obstacles.hit(body.boxes(out, np.arctan2(g[:, 1], g[:, 0]), grid.curb_h)).any() else out


def _shift_rows(grid: Grid, line: Line, t: np.ndarray, offs, obstacles: wc.Obstacles, body: wc.Body,
                t_start: float, t_end: float) -> np.ndarray | None:
    """(n, 2) shifted points at ``t`` (a stretch of a piece from ``t_start`` to ``t_end``), zero shift at both ends."""
    xy = line.xy(t)
    yaw = float(np.arctan2(line.u[1], line.u[0]))
    off, step = offs[line.fam], wc.SHIFT_STEP_M
    rh, wi, ch, hy = grid.road_half, grid.walk_inner, grid.corridor_half, body.hy
    near_node = np.abs(t[:, None] - (grid.xs if line.axis == 0 else grid.ys)[None]).min(1) < ch
    lo = np.where(near_node, rh + CROSSWALK_U[0] + 0.1, wi + hy + 0.05)
    hi = np.where(near_node, rh + CROSSWALK_U[1] - 0.1, ch - hy - 0.1)
    reach = int(np.ceil(3 * SIGMA_M / ROW_M)) * ROW_M + 1e-9     # how far smoothing spreads a shift
    end = np.minimum(np.abs(t - t_start), np.abs(t - t_end))
    fixed = (end < FIX_M + reach) | (np.minimum(np.abs(t - t[0]), np.abs(t - t[-1])) < reach)   # no shift here ...
    k0 = int(np.ceil(max(0.0, off - lo.min()) / step))
    cols = off + (np.arange(k0 + int(np.ceil(max(0.0, hi.max() - off) / step)) + 1) - k0) * step
    o = np.broadcast_to(cols, (len(t), len(cols)))
    ok = ((o >= lo[:, None]) & (o <= hi[:, None]) & ~fixed[:, None]) | (np.arange(len(cols)) == k0)[None]
    pts = line.xy(np.repeat(t, len(cols))) + (o.ravel() - off)[:, None] * line.n
    ok &= ~obstacles.hit(body.boxes(pts, np.full(len(pts), yaw), grid.curb_h, grow=0.05)).reshape(o.shape)
    cost = np.abs(cols - off) / step
    if len(offs) > 1:          # borrowing the other direction's half of the sidewalk costs more
        mid = (offs[0] + offs[-1]) / 2
        cost = cost + OTHER_COST * np.maximum(0.0, (cols - mid) if line.fam == KERB else (mid - cols)) / step
    path = wc.shift_path(np.where(ok, cost[None], np.inf), k0)
    if path is None:
        return None
    delta = wc.smooth(cols[path] - off, SIGMA_M / ROW_M)
    delta[end < FIX_M] = 0.0                # ... so smoothing leaves none here or at the stretch ends (exactly)
    return xy + delta[:, None] * line.n


def obstacles_of(grid: Grid, scene, body: wc.Body) -> wc.Obstacles:
    """The static obstacles of ``scene`` a walker of ``body`` can meet on the pavement of ``grid``."""
    reach = grid.corridor_half + 2.0
    # near: objects wholly beyond ``reach`` (+ 1 um for the tiles' rounding) of every street need no tiles
    return wc.Obstacles(scene, grid.curb_h + body.height + 0.1, keep=lambda xy: street_distance(grid, xy) < reach,
                        near=lambda rects: street_distance_bound(grid, rects) < reach + 1e-6)


def build_walkways(grid: Grid, obstacles: wc.Obstacles, body: wc.Body) -> Walkways:
    """The walk network of ``grid`` clear of ``obstacles`` (:func:`obstacles_of`) for walkers of ``body``."""
    offs = lane_offsets(grid, body)
    if not offs:
        log.warning("sidewalks of %.2f m are too narrow for walkers", grid.sidewalk_w)
        return Walkways([], [], [], np.zeros((0, 2)), np.zeros(0), offs)
    lns = lines(grid, offs)
    trn = turns(grid, lns, offs)
    # junctions per line: along-coordinate -> (turns departing, turns arriving)
    marks: dict[tuple, dict[float, tuple[list, list]]] = {k: {} for k in lns}
    for ti, (kin, kout, p) in enumerate(trn):
        marks[kin].setdefault(round(along(lns[kin], p) - R_TURN * lns[kin].d, 6), ([], []))[0].append(ti)
        marks[kout].setdefault(round(along(lns[kout], p) + R_TURN * lns[kout].d, 6), ([], []))[1].append(ti)
    geoms: list[np.ndarray | None] = []
    succ: list[list[int]] = []
    start_of: dict[tuple, int] = {}       # (line key, along) -> edge starting there
    ends: list[tuple] = []                 # per piece: (line key, along of its end)
    for key, line in lns.items():
        for a0, a1 in itertools.pairwise(sorted(marks[key], key=lambda a, line=line: a * line.d)):
            start_of[(key, a0)] = len(geoms)
            ends.append((key, a1))
            t = np.linspace(a0, a1, max(2, int(np.ceil(abs(a1 - a0) / ROW_M)) + 1))
            geoms.append(_shifted(grid, line, t, offs, obstacles, body))
            succ.append([])
    n_pieces = len(geoms)
    for kin, kout, p in trn:
        xy = arc(p, lns[kin].u, lns[kout].u, SAMPLE_M)
        d = np.gradient(xy, axis=0)
        blocked = obstacles.hit(body.boxes(xy, np.arctan2(d[:, 1], d[:, 0]), grid.curb_h)).any()
        geoms.append(None if blocked else xy)
        b = round(along(lns[kout], p) + R_TURN * lns[kout].d, 6)
        succ.append([start_of[(kout, b)]] if (kout, b) in start_of else [])
    for e, (key, a1) in enumerate(ends):
        if (key, a1) in start_of:
            succ[e].append(start_of[(key, a1)])
        succ[e].extend(n_pieces + ti for ti in marks[key][a1][0])
    return _assemble(grid, geoms, succ, offs, body)


def _prune(geoms: list, succ: list[list[int]]) -> np.ndarray:
    """(E,) bool: edges that are clear and both reachable from and leading to another live edge."""
    alive = np.array([g is not None for g in geoms])
    while True:
        has_succ = np.array([alive[e] and any(alive[s] for s in succ[e]) for e in range(len(succ))])
        has_pred = np.zeros(len(succ), bool)
        for e in np.flatnonzero(has_succ):
            for s in succ[e]:
                has_pred[s] |= True
        new = alive & has_succ & has_pred
        if (new == alive).all():
            return alive
        alive = new


def _assemble(grid: Grid, geoms: list, succ: list[list[int]], offs, body: wc.Body) -> Walkways:
    alive = _prune(geoms, succ)
    ids = -np.ones(len(geoms), np.int64)
    ids[alive] = np.arange(alive.sum())
    log.info("walk network: %d edges (%d cut round obstacles or dead ends)", alive.sum(), len(geoms) - alive.sum())
    paths, out_succ, nodes, road, stop = [], [], [], [], []
    rh, wi = grid.road_half, grid.walk_inner
    edges, samples = np.flatnonzero(alive), []
    for e in edges:
        xy = geoms[e]
        s = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(xy, axis=0), axis=1))]
        n = max(2, int(np.ceil(s[-1] / SAMPLE_M)) + 1)
        su = np.linspace(0.0, s[-1], n)
        samples.append((su, np.stack([np.interp(su, s, xy[:, 0]), np.interp(su, s, xy[:, 1])], -1)))
    # point by point: asked once for every edge's samples (each call walks every road rectangle)
    dists, heights = [], []
    if samples:
        cut = np.cumsum([len(su) for su, _ in samples])[:-1]
        every = np.concatenate([xy for _, xy in samples])
        dists, heights = np.split(street_distance(grid, every), cut), np.split(grid.ground_height(every), cut)
    for e, (su, xy), d, z in zip(edges, samples, dists, heights, strict=True):
        g = np.gradient(xy, axis=0)
        paths.append(Path(f"walk_{len(paths):04d}", np.column_stack([xy, z]), np.arctan2(g[:, 1], g[:, 0]), su))
        out_succ.append(tuple(int(ids[k]) for k in succ[e] if alive[k]))
        on_road = np.flatnonzero(d < rh)
        if len(on_road):
            mid = xy[on_road[len(on_road) // 2]]
            i, j = int(np.abs(grid.xs - mid[0]).argmin()), int(np.abs(grid.ys - mid[1]).argmin())
            nodes.append((i, j))
            road.append((su[on_road[0]], su[on_road[-1]]))
            stop.append(su[np.flatnonzero(d < wi)[0]] - body.hx - 0.05)
        else:
            nodes.append(None)
            road.append((np.nan, np.nan))
            stop.append(np.nan)
    return Walkways(paths, out_succ, nodes, np.array(road, np.float64).reshape(-1, 2), np.array(stop, np.float64),
                    offs)

