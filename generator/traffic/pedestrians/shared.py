"""People standing on the carriageway of shared streets, where moving traffic cannot reach them.

With moving traffic on, walkers keep to the sidewalks and the signalled crosswalks
(:mod:`generator.traffic.pedestrians.sim`): the vehicles never see a person except through the
signals, so a walker crossing a shared street mid-block could meet a car. What is safe is the
paving beside the lanes: the *furnished* strips of a shared street
(:mod:`generator.layout.placement.shared_streets`) hold bollards, not parked cars, and no vehicle drives
there. :func:`shared_standers` puts ``traffic.standing_pedestrians_per_100m`` people per 100 m of
such strip on it, at road level, outside the reach of the widest vehicle the spec's traffic drives
(mirrors included, :func:`generator.traffic.vehicles.fleet.widest_half_width`) on the outer lane's
centre, plus :data:`CLEAR_M`, and :data:`END_CLEAR_M` inside the strip's ends, clear of the bollards
and of each other.

Randomness: stander ``k`` draws from ``("traffic", "pedestrian", "shared", k)``.
"""

from __future__ import annotations

import logging

import numpy as np

from generator.geometry.boxes import box_pairs_overlap
from generator.layout.network.cross_sections import shared_segments
from generator.layout.network.measures import PARKING_START_U
from generator.layout.placement.appearance import outfit
from generator.rng import stream
from generator.traffic.movers import Mover
from generator.traffic.pedestrians import clear as wc
from generator.world.actors import Track

log = logging.getLogger(__name__)

CLEAR_M = 0.2            #: a margin beyond the widest vehicle's side
KERB_CLEAR_M = 0.3       #: a stander's box keeps this far from the curb face
END_CLEAR_M = 4.0        #: ... and this far past the strip's ends (a turning bus swings its rear)
TRIES = 100


def shared_standers(spec, grid, obstacles: wc.Obstacles, protos, n_steps: int, dt: float, cls: str,
                    box_of, vehicle_half_width: float) -> list[Mover]:
    """Standing people in the furnished strips of the shared streets (empty without any).

    Parameters
    ----------
    spec : SceneSpec
    grid : Grid
    obstacles : generator.traffic.pedestrians.clear.Obstacles
        The static town's obstacles (bollards included).
    protos : list of Proto
        Standing person prototypes.
    n_steps : int
        Track samples from t = 0, every ``dt`` seconds.
    cls : str
        Native class of a person.
    box_of : callable
        ``box_of(proto, x, y, z, yaw, grow) -> (1, 7)`` footprint box (``pedestrians._proto_box``).
    vehicle_half_width : float
        Half width of the widest vehicle that may drive the lanes, mirrors included, metres.

    Returns
    -------
    list of Mover
        Role ``"standing"``, placement ``"shared_street"``; z = 0 (the road surface).
    """
    e0 = PARKING_START_U + END_CLEAR_M
    segs = [s for s in shared_segments(grid) if s.length - 2 * e0 > 1.0]
    v0 = grid.lane_half - grid.lane_w / 2 + vehicle_half_width + CLEAR_M
    v1 = grid.road_half - KERB_CLEAR_M
    dens = spec.traffic.standing_pedestrians_per_100m
    if not segs or dens <= 0 or v1 - v0 < 0.2:
        return []
    w = np.array([s.length - 2 * e0 for s in segs])
    n = round(dens * 2 * w.sum() / 100.0)
    placed, out = np.zeros((0, 7)), []
    for k in range(n):
        g = stream(spec.seed, "traffic", "pedestrian", "shared", k)
        proto, look = protos[int(g.integers(len(protos)))], outfit(g)
        for _ in range(TRIES):
            seg = segs[int(g.choice(len(segs), p=w / w.sum()))]
            yaw = float(g.uniform(-np.pi, np.pi))
            u = g.uniform(e0, seg.length - e0)
            x, y = seg.to_world(u, g.choice([-1, 1]) * g.uniform(v0, v1))[0]
            box = box_of(proto, x, y, 0.0, yaw, 0.05)
            if not _inside_strip(grid, seg, box, v0, v1) or obstacles.hit(box).any():
                continue
            if len(placed) and box_pairs_overlap(np.repeat(box, len(placed), 0), placed).any():
                continue
            placed = np.vstack([placed, box])
            out.append(Mover("person", cls, proto, Track(0.0, dt, np.repeat([[x, y, 0.0]], n_steps, 0),
                                                         np.full(n_steps, yaw)),
                             {**look, "role": "standing", "placement": "shared_street"}))
            break
        else:
            log.warning("no room for shared-street stander %d of %d; placed %d", k + 1, n, len(out))
            break
    return out


def _inside_strip(grid, seg, box: np.ndarray, v0: float, v1: float) -> bool:
    """True when the (1, 7) box's corners all lie at ``v0 <= |v| <= v1`` on one side of ``seg``."""
    x, y, hx, hy, yaw = box[0, :5]
    c, s = np.cos(yaw), np.sin(yaw)
    corners = np.array([[x + a * hx * c - b * hy * s, y + a * hx * s + b * hy * c] for a in (-1, 1) for b in (-1, 1)])
    d = corners - np.asarray(seg.origin)
    v = d[:, 1] if seg.axis == 0 else -d[:, 0]
    return bool(((np.abs(v) >= v0) & (np.abs(v) <= v1)).all() and len(set(np.sign(v))) == 1)
