"""Pedestrians in motion: properties a user of the traffic data relies on.

One small town (``scenes/test_town.json`` with walking and standing pedestrians switched on)
is simulated once for a whole signal cycle; every test reads those tracks. Geometry checks
are written out here (footprint overlap, walkable surface), not borrowed from the code under
test. Static obstacles are the objects' collision bands (the layout's own definition of what
occupies space, :func:`generator.layout.placement.prototypes.collision_boxes`): a person may walk
under a tree crown or a lamp arm, not through a trunk or a pole.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.spatial import cKDTree

from generator.geometry.boxes import world_boxes
from generator.layout.network.draw import make_grid
from generator.layout.network.measures import CROSSWALK_U
from generator.layout.placement.prototypes import WHOLE_BOX_KINDS, Library, collision_boxes
from generator.traffic.lanes.signals import CYCLE_S, WALK_S, Signals
from generator.traffic.movers import DT_S
from generator.traffic.pedestrians import clear as walk_clear
from generator.traffic.pedestrians import net as walk_net
from generator.traffic.pedestrians.simulate import (
    MARGIN_M,
    max_speed,
    person_protos,
    sidewalk_length,
    simulate_pedestrians,
)
from generator.traffic.pedestrians.walkways import build_walkways, obstacles_of

N_STEPS = int(CYCLE_S / DT_S)          # one whole signal cycle: every node has a walk phase
GROUND = {"road", "road_marking", "crosswalk", "curb", "sidewalk", "parking", "terrain", "other_ground", "rail_track"}


def _with_traffic(spec, walking: float, standing: float):
    return dataclasses.replace(spec, traffic=dataclasses.replace(
        spec.traffic, pedestrians_per_100m=walking, standing_pedestrians_per_100m=standing))


def _simulate(spec, scene, n_steps=N_STEPS):
    grid = make_grid(spec)
    return simulate_pedestrians(spec, grid, scene, Signals(spec.seed, grid.nodes), Library(spec.seed), n_steps, DT_S)


@pytest.fixture(scope="module")
def town(test_spec, test_scene):
    """(spec, grid, signals, movers): the test town with 12 walkers and 3 standers per 100 m.

    The layout does not read the traffic block, so the session's test scene is this town's.
    """
    spec = _with_traffic(test_spec, 12.0, 3.0)
    grid = make_grid(spec)
    return spec, grid, Signals(spec.seed, grid.nodes), _simulate(spec, test_scene)


@pytest.fixture(scope="module")
def tracks(town):
    """(xyz (n, T, 3), yaw (n, T), walking (n,) bool, lo (n, 3), hi (n, 3)) of every pedestrian."""
    movers = town[3]
    return (np.stack([m.track.xyz for m in movers]), np.stack([m.track.yaw for m in movers]),
            np.array([m.attrs["role"] == "walking" for m in movers]),
            np.stack([m.proto.lo for m in movers]), np.stack([m.proto.hi for m in movers]))


# -- geometry written out for the tests ----------------------------------------------------------
def _street_distance(grid, xy):
    """L-infinity distance of (n, 2) points to the nearest street centre segment."""
    out = np.full(len(xy), np.inf)
    for y in grid.ys:      # east-west streets
        beyond = np.maximum(np.maximum(grid.xs[0] - xy[:, 0], xy[:, 0] - grid.xs[-1]), 0)
        out = np.minimum(out, np.maximum(np.abs(xy[:, 1] - y), beyond))
    for x in grid.xs:
        beyond = np.maximum(np.maximum(grid.ys[0] - xy[:, 1], xy[:, 1] - grid.ys[-1]), 0)
        out = np.minimum(out, np.maximum(np.abs(xy[:, 0] - x), beyond))
    return out


def _crosswalk_node(grid, xy):
    """(n,) index into ``grid.nodes`` of the crosswalk band (on the road) each point is on, -1 if none."""
    out = np.full(len(xy), -1)
    for seg in grid.segments:
        d = xy - np.asarray(seg.origin)
        u, v = (d[:, 0], d[:, 1]) if seg.axis == 0 else (d[:, 1], -d[:, 0])
        on_road = np.abs(v) < grid.road_half
        for from_edge, node in ((u, seg.a), (seg.length - u, seg.b)):
            band = (from_edge >= CROSSWALK_U[0]) & (from_edge <= CROSSWALK_U[1]) & on_road
            out[band] = grid.nodes.index(node)
    return out


def _corners(c, half, yaw):
    """(k, 4, 2) footprint corners of boxes with centres (k, 2), half sizes (k, 2), headings (k,)."""
    cs, sn = np.cos(yaw)[:, None], np.sin(yaw)[:, None]
    lx = np.array([-1, 1, 1, -1]) * half[:, :1]
    ly = np.array([-1, -1, 1, 1]) * half[:, 1:]
    return np.stack([c[:, :1] + lx * cs - ly * sn, c[:, 1:] + lx * sn + ly * cs], -1)


def _overlap(a, b):
    """(k,) bool: do convex quads ``a[i]`` and ``b[i]`` ((k, 4, 2)) overlap (no separating edge normal)?"""
    sep = np.zeros(len(a), bool)
    for q in (a, b):
        for i in range(4):
            edge = q[:, (i + 1) % 4] - q[:, i]
            n = np.stack([-edge[:, 1], edge[:, 0]], -1)
            pa, pb = np.einsum("kij,kj->ki", a, n), np.einsum("kij,kj->ki", b, n)
            sep |= (pa.max(1) <= pb.min(1)) | (pb.max(1) <= pa.min(1))
    return ~sep


def _footprints(xyz, yaw, lo, hi, t):
    """Footprint corners (n, 4, 2) and z intervals (n, 2) of every pedestrian at sample ``t``."""
    c = (lo[:, :2] + hi[:, :2]) / 2
    cs, sn = np.cos(yaw[:, t]), np.sin(yaw[:, t])
    centre = xyz[:, t, :2] + np.stack([c[:, 0] * cs - c[:, 1] * sn, c[:, 0] * sn + c[:, 1] * cs], -1)
    z = xyz[:, t, 2:3] + np.stack([lo[:, 2], hi[:, 2]], -1)
    return _corners(centre, (hi[:, :2] - lo[:, :2]) / 2, yaw[:, t]), z


# -- the tests ------------------------------------------------------------------------------------
def test_town_has_walkers_and_standers(town, tracks):
    spec, grid, _, movers = town
    walking = tracks[2]
    assert walking.sum() == round(12.0 * sidewalk_length(grid) / 100)
    assert (~walking).sum() == round(3.0 * sidewalk_length(grid) / 100)
    for m in movers:
        assert (m.kind, m.cls) == ("person", "person")
        assert m.proto.key.startswith("person_v") and m.proto.params["pose"] == m.attrs["role"]
        assert len(m.attrs["color"]) == 3 and m.track.t0 == 0.0 and m.track.dt == DT_S
        assert m.track.xyz.shape == (N_STEPS, 3)
        low = 0.95 if m.attrs["role"] == "walking" else 1.0      # a walker's knees are never quite straight
        assert low * spec.heights.person_m[0] <= m.proto.hi[2] <= spec.heights.person_m[1] + 0.05


def test_walkers_stay_on_sidewalks_and_crosswalks(town, tracks):
    grid = town[1]
    xy = tracks[0][..., :2].reshape(-1, 2)
    d = _street_distance(grid, xy)
    sidewalk = (d >= grid.walk_inner) & (d <= grid.corridor_half)
    crosswalk = _on_crosswalk_band(grid, xy)          # across the road and its curbs
    ok = sidewalk | crosswalk
    assert ok.all(), f"{(~ok).sum()} samples off the pavement, e.g. {xy[~ok][:3]}"
    assert not ((d < grid.lane_half) & ~crosswalk).any(), "a pedestrian on the driving lanes outside a crosswalk"


def _on_crosswalk_band(grid, xy):
    """(n,) bool: inside a crosswalk band across the whole corridor (curbs included)."""
    out = np.zeros(len(xy), bool)
    for seg in grid.segments:
        d = xy - np.asarray(seg.origin)
        u, v = (d[:, 0], d[:, 1]) if seg.axis == 0 else (d[:, 1], -d[:, 0])
        for from_edge in (u, seg.length - u):
            out |= (from_edge >= CROSSWALK_U[0]) & (from_edge <= CROSSWALK_U[1]) & (np.abs(v) <= grid.walk_inner)
    return out


def test_pedestrians_are_on_crosswalks_only_during_the_walk_phase(town, tracks):
    grid, signals = town[1], town[2]
    xyz = tracks[0]
    node = _crosswalk_node(grid, xyz[..., :2].reshape(-1, 2))
    t = np.tile(np.arange(xyz.shape[1]) * DT_S, len(xyz))
    on = np.flatnonzero(node >= 0)
    assert len(on) > 100, "nobody crossed a street in a whole signal cycle"
    phase = np.array([signals.phase(grid.nodes[node[k]], t[k]) for k in on])
    assert (phase < WALK_S).all(), f"{(phase >= WALK_S).sum()} samples on a crosswalk outside the walk phase"


def test_no_two_pedestrians_overlap(tracks):
    xyz, yaw, _, lo, hi = tracks
    reach = 2 * np.hypot(np.abs([lo, hi]).max((0, 1))[0], np.abs([lo, hi]).max((0, 1))[1])
    touching = 0
    for t in range(xyz.shape[1]):
        quads, z = _footprints(xyz, yaw, lo, hi, t)
        pairs = cKDTree(xyz[:, t, :2]).query_pairs(reach, output_type="ndarray")
        if len(pairs):
            i, j = pairs[:, 0], pairs[:, 1]
            touching += int((_overlap(quads[i], quads[j]) & (z[i, 0] < z[j, 1]) & (z[j, 0] < z[i, 1])).sum())
    assert touching == 0


def test_no_pedestrian_enters_a_static_object(town, tracks, test_scene):
    xyz, yaw, _, lo, hi = tracks
    bands = []
    for o in test_scene.objects:
        if o.cls not in GROUND:
            wb = world_boxes(collision_boxes(test_scene.prototypes[o.prototype], whole=o.kind in WHOLE_BOX_KINDS),
                             o.transform)
            bands.append(wb)
    bands = np.concatenate(bands)            # (m, 7): cx, cy, hx, hy, yaw, z0, z1
    quads_b = _corners(bands[:, :2], bands[:, 2:4], bands[:, 4])
    # broad phase: a pedestrian can touch a band only within the band's and its own bounding radii;
    # small bands by a k-d tree at the largest small radius, large ones (buildings, fences, the far
    # city's blocks and tree lines, up to ~100 m) each at its own radius
    r_ped = max(1.0, float(np.hypot(*np.abs([lo[:, :2], hi[:, :2]]).max((0, 1)))) * 2)
    r_band = np.hypot(bands[:, 2], bands[:, 3])
    small, large = np.flatnonzero(r_band <= 3.0), np.flatnonzero(r_band > 3.0)
    tree = cKDTree(bands[small, :2])
    reach = r_band[small].max() + r_ped
    for t in range(0, xyz.shape[1], 2):
        quads, z = _footprints(xyz, yaw, lo, hi, t)
        near = tree.query_ball_point(xyz[:, t, :2], reach)
        i = np.repeat(np.arange(len(near)), [len(n) for n in near])
        j = small[np.concatenate([np.asarray(n, int) for n in near])]
        il, jl = np.nonzero(np.linalg.norm(xyz[:, t, None, :2] - bands[None, large, :2], axis=-1)
                            <= r_band[large] + r_ped)
        i, j = np.r_[i, il], np.r_[j, large[jl]]
        hit = _overlap(quads[i], quads_b[j]) & (z[i, 0] < bands[j, 6]) & (bands[j, 5] < z[i, 1])
        assert not hit.any(), f"t={t * DT_S:.2f}: pedestrian {i[hit][0]} inside a static object"


def test_motion_is_continuous_with_bounded_speed_acceleration_and_turn_rate(town, tracks):
    xyz, yaw, walking = tracks[:3]
    v = np.diff(xyz[walking, :, :2], axis=1) / DT_S
    speed = np.linalg.norm(v, axis=2)
    assert speed.max() <= max_speed(town[0]) + 1e-6                        # no teleports
    ground = town[1].ground_height(xyz[..., :2].reshape(-1, 2)).reshape(xyz.shape[:2])
    assert np.array_equal(xyz[..., 2], ground)                             # feet on the ground: a kerb is a step
    assert set(np.round(np.abs(np.diff(xyz[..., 2], axis=1)), 9).ravel()) <= {0.0, round(town[1].curb_h, 9)}
    tangential = np.diff(speed, axis=1) / DT_S
    assert tangential.max() <= walk_net.A_MAX + 0.05 and tangential.min() >= -walk_net.B_MAX - 0.05
    total = np.linalg.norm(np.diff(v, axis=1), axis=2) / DT_S
    assert total.max() <= np.hypot(walk_net.B_MAX, walk_net.A_LAT) + 0.4    # braking and turning together
    assert np.abs(np.diff(yaw, axis=1)).max() <= walk_net.YAW_RATE * DT_S + 1e-9


def test_walkers_walk_and_wait_facing_the_way_they_go(tracks):
    xyz, yaw, walking = tracks[:3]
    speed = np.linalg.norm(np.diff(xyz[walking, :, :2], axis=1), axis=2) / DT_S
    assert np.median(speed) > 0.5                                          # most of the time they walk
    assert (speed.max(1) > 0.8).mean() > 0.9                               # nearly all get going in one cycle
    assert (speed < 0.05).any()                                            # ... and some wait
    moving = speed > 0.5
    heading = np.arctan2(*np.diff(xyz[walking, :, :2], axis=1).transpose(2, 0, 1)[::-1])
    off = np.abs(np.angle(np.exp(1j * (heading - yaw[walking, 1:]))))
    assert np.percentile(off[moving], 99) < 0.2                            # they face where they walk


def test_standers_stand_still_on_the_pavement(town, tracks):
    grid = town[1]
    xyz, yaw, walking = tracks[:3]
    stand = ~walking
    assert stand.any()
    assert (np.ptp(xyz[stand], axis=1) == 0).all() and (np.ptp(yaw[stand], axis=1) == 0).all()
    d = _street_distance(grid, xyz[stand, 0, :2])
    assert ((d >= grid.walk_inner) & (d <= grid.corridor_half)).all()


def test_same_seed_same_tracks(town, test_scene):
    spec, movers = town[0], town[3]
    again = _simulate(spec, test_scene)
    assert len(again) == len(movers)
    for a, b in zip(movers, again, strict=True):
        assert a.proto.key == b.proto.key and a.attrs == b.attrs
        assert np.array_equal(a.track.xyz, b.track.xyz) and np.array_equal(a.track.yaw, b.track.yaw)


def test_zero_density_means_no_pedestrians(test_spec, test_scene):
    assert _simulate(_with_traffic(test_spec, 0.0, 0.0), test_scene, 10) == []


def test_density_scales_the_counts(test_spec, test_scene):
    counts = {}
    for d in (2.0, 4.0):
        movers = _simulate(_with_traffic(test_spec, d, d / 2), test_scene, 2)
        counts[d] = (sum(m.attrs["role"] == "walking" for m in movers), sum(m.attrs["role"] == "standing"
                                                                            for m in movers))
    length = sidewalk_length(make_grid(test_spec))
    for d, (walk, stand) in counts.items():
        assert (walk, stand) == (round(d * length / 100), round(d / 2 * length / 100))
    assert counts[4.0][0] >= 2 * counts[2.0][0] - 1


def test_walk_network_joins_smoothly_keeps_right_and_tags_crosswalks(town, test_scene):
    spec, grid = town[0], town[1]
    standing, walking = person_protos(Library(spec.seed), spec)
    ww = build_walkways(grid, obstacles_of(grid, test_scene, walk_clear.body_of(walking + standing, MARGIN_M)),
                        walk_clear.body_of(walking + standing, MARGIN_M))
    assert len(ww.paths) > 50 and len(ww.offsets) == 2
    kerb, lot = ww.offsets
    crossings, checked = set(), {True: 0, False: 0}
    for e, p in enumerate(ww.paths):
        assert ww.succ[e], "an edge that leads nowhere"
        for f in ww.succ[e]:                          # joined end to start, heading continuous
            q = ww.paths[f]
            assert np.linalg.norm(p.points[-1, :2] - q.points[0, :2]) < 1e-6
            assert abs(np.angle(np.exp(1j * (p.headings[-1] - q.headings[0])))) < 0.05
        xy = p.points[:, :2]
        node = _crosswalk_node(grid, xy)
        on_road = _street_distance(grid, xy) < grid.road_half
        assert (node[on_road] >= 0).all(), "an edge crosses a road outside a crosswalk band"
        if on_road.any():
            assert set(node[on_road]) == {grid.nodes.index(ww.node[e])}
            crossings.add(ww.node[e])
        else:
            assert ww.node[e] is None
        # keep right: on a straight stretch of sidewalk at a nominal offset, the kerb line has the
        # road on the walker's right and the lot line has it on the left
        d = _street_distance(grid, xy)
        dx, dy = np.cos(p.headings), np.sin(p.headings)
        for centres, axis in ((grid.ys, 1), (grid.xs, 0)):
            off = xy[:, axis, None] - centres[None]
            k = np.abs(off).argmin(1)
            v = off[np.arange(len(xy)), k]
            along = np.abs(dx if axis == 1 else dy) > 0.999
            for nominal, road_right in ((kerb, True), (lot, False)):
                at = along & (np.abs(np.abs(v) - nominal) < 1e-6) & (d >= grid.walk_inner)
                # the road lies across the centre line (towards -sign(v)); the walker's right is (dy, -dx)
                right = np.sign(v) * (dx if axis == 1 else -dy) > 0
                assert at.sum() == 0 or (right[at] == road_right).all()
                checked[road_right] += int(at.sum())
    assert min(checked.values()) > 1000               # both directions of many sidewalks were checked
    assert len(crossings) == len(grid.nodes)          # every node's crosswalks are in the network
