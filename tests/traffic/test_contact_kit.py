"""The traffic tests' contact kit (tests/kits/traffic_contacts.py) is never weaker than shapely.

The kit's numpy separating-axis test replaced shapely's polygon intersection to judge every time
step of the simulations faster; a kit that missed a touch would let colliding traffic pass. Here
it is held to shapely on random boxes and on touching and near-miss pairs built on purpose: every
pair shapely finds touching the kit finds touching, and the kit says more only of pairs closer
than a micrometre (it counts a gap below ``SLACK_M`` as contact).
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from kits.traffic_contacts import SLACK_M, Box, footprint, footprints, quads_touch, touching


def _random_boxes(rng, n: int, spread: float) -> list[Box]:
    xy = rng.uniform(-spread, spread, (n, 2))
    size = rng.uniform([0.3, 0.3], [12.0, 3.0], (n, 2))
    yaw = rng.uniform(-np.pi, np.pi, n)
    return [Box((x, y, 0.75), (length, width, 1.5), h) for (x, y), (length, width), h in zip(xy, size, yaw,
                                                                                             strict=True)]


def _shapely_touching(qa: np.ndarray, qb: np.ndarray) -> np.ndarray:
    pa, pb = shapely.polygons(qa), shapely.polygons(qb)
    return shapely.intersects(pa[:, None], pb[None]), shapely.distance(pa[:, None], pb[None])


def _touching_pairs(rng, n: int) -> tuple[list[Box], list[Box]]:
    """``n`` pairs that touch exactly (edge on edge, corner on edge, corner on corner), each turned
    by a random yaw about a random point, and the same pairs pushed apart or together by 1 um to 1 cm."""
    a, b = [], []
    for _ in range(n):
        la, wa, lb, wb = rng.uniform(0.5, 12.0), rng.uniform(0.5, 3.0), rng.uniform(0.5, 12.0), rng.uniform(0.5, 3.0)
        how = rng.integers(3)
        if how == 0:        # b's rear edge on a's front edge, shifted sideways
            off = np.array([(la + lb) / 2, rng.uniform(-(wa + wb) / 2, (wa + wb) / 2)])
            yb = 0.0
        elif how == 1:      # b's corner on a's side, b turned
            yb = rng.uniform(0.1, np.pi / 2 - 0.1)
            c, s = np.cos(yb), np.sin(yb)
            corner = np.array([[-lb / 2, -wb / 2], [lb / 2, -wb / 2], [lb / 2, wb / 2], [-lb / 2, wb / 2]]) \
                @ np.array([[c, s], [-s, c]])
            low = corner[np.argmin(corner[:, 1])]
            off = np.array([rng.uniform(-la / 2, la / 2), wa / 2]) - low
        else:               # corner on corner
            off = np.array([(la + lb) / 2, (wa + wb) / 2])
            yb = 0.0
        for push in (0.0, rng.choice([-1, 1]) * 10.0 ** rng.uniform(-6, -2)):
            yaw = rng.uniform(-np.pi, np.pi)
            c, s = np.cos(yaw), np.sin(yaw)
            rot = np.array([[c, -s], [s, c]])
            o = rng.uniform(-50, 50, 2)
            shift = off + push * off / np.linalg.norm(off)
            a.append(Box((*o, 0.75), (la, wa, 1.5), yaw))
            b.append(Box((*(o + rot @ shift), 0.75), (lb, wb, 1.5), yaw + yb))
    return a, b


@pytest.mark.parametrize("seed, spread", [(1, 6.0), (2, 12.0), (3, 25.0)])
def test_the_kit_says_what_shapely_says_on_random_boxes(seed, spread):
    """300 x 300 random pairs: the same answer as shapely on every pair (none lies within a micrometre)."""
    rng = np.random.default_rng(seed)
    qa, qb = footprints(_random_boxes(rng, 300, spread)), footprints(_random_boxes(rng, 300, spread))
    kit = touching(qa, qb)
    ref, gap = _shapely_touching(qa, qb)
    assert 1000 < ref.sum() < ref.size - 1000          # both answers occur often
    assert not (ref & ~kit).any()                      # never misses a touch
    assert np.array_equal(kit, ref) or (gap[kit != ref] < 1e-6).all()


def test_the_kit_finds_every_touch_and_calls_only_micrometre_gaps_contact():
    """Pairs that touch exactly and pairs pushed 1 um - 1 cm apart or together: every pair shapely
    says touches the kit says touches; a pair the kit says touches that shapely does not is less
    than a micrometre apart."""
    rng = np.random.default_rng(7)
    a, b = _touching_pairs(rng, 400)
    qa, qb = footprints(a), footprints(b)
    kit = quads_touch(qa, qb)
    assert np.array_equal(np.diag(touching(qa, qb)), kit)              # the broad phase drops no pair
    pa, pb = shapely.polygons(qa), shapely.polygons(qb)
    ref, gap = shapely.intersects(pa, pb), shapely.distance(pa, pb)
    assert not (ref & ~kit).any(), np.flatnonzero(ref & ~kit)[:5]
    assert (gap[kit & ~ref] < 1e-6).all()
    apart = gap > 1e-6
    assert apart.sum() > 100 and not kit[apart].any()                  # real gaps are seen as gaps
    assert kit.sum() > 400                                              # the exact touches are found


def test_the_broad_phase_drops_no_pair():
    rng = np.random.default_rng(11)
    qa, qb = footprints(_random_boxes(rng, 120, 15.0)), footprints(_random_boxes(rng, 90, 15.0))
    i, j = np.meshgrid(np.arange(len(qa)), np.arange(len(qb)), indexing="ij")
    every = quads_touch(qa[i.ravel()], qb[j.ravel()]).reshape(len(qa), len(qb))
    assert np.array_equal(touching(qa, qb), every) and 0 < every.sum() < every.size


@pytest.mark.parametrize("gap, want", [(0.0, True), (SLACK_M / 2, True), (1e-6, False), (-1e-6, True)])
def test_edge_to_edge_counts_as_contact_and_a_micrometre_does_not(gap, want):
    a = Box((0, 0, 0), (4.0, 2.0, 1), 0.3)
    c, s = np.cos(0.3), np.sin(0.3)
    b = Box(((4.0 + gap) * c, (4.0 + gap) * s, 0), (4.0, 2.0, 1), 0.3)
    assert touching(footprint(a)[None], footprint(b)[None])[0, 0] == want
    assert touching(footprint(b)[None], footprint(a)[None])[0, 0] == want


def test_empty_inputs_touch_nothing():
    q = footprint(Box((0, 0, 0), (4.0, 2.0, 1), 0.0))[None]
    assert touching(q, np.zeros((0, 4, 2))).shape == (1, 0) and touching(np.zeros((0, 4, 2)), q).shape == (0, 1)


def test_actor_footprints_are_the_footprints_of_the_actors_boxes():
    """The kit's footprints (and box centres and yaws) of all actors at once equal those of :meth:`Actor.box` at
    any instant: between samples, on them, before a track starts and after it ends (held), for
    tracks of different starts, spacings and lengths (a one-sample track included)."""
    from types import SimpleNamespace

    from generator.world.actors import Actor, Track
    from kits.traffic_contacts import actor_poses, actor_quads

    rng = np.random.default_rng(5)
    actors = []
    for k, n in enumerate((1, 2, 7, 40, 41, 300)):
        xyz = np.cumsum(rng.normal(0, 0.5, (n, 3)), 0)
        track = Track(float(rng.uniform(-1, 1)), float(rng.choice([0.1, 0.05, 0.2])), xyz,
                      np.cumsum(rng.normal(0, 0.2, n)))
        actors.append(Actor(k, f"a{k}", "car", "car", k + 1, "p", tuple(rng.uniform(0.5, 5.0, 3)),
                            tuple(rng.uniform(-1, 1, 3)), track))
    world = SimpleNamespace(actors=actors)
    for t in np.r_[-3.0, rng.uniform(-1.5, 70.0, 200), 0.0, 0.1, 100.0]:
        own = footprints([a.box(t) for a in actors])
        assert np.abs(actor_quads(world, t) - own).max() < 1e-9, t
        assert np.abs(actor_quads(world, t, actors[2:4]) - own[2:4]).max() < 1e-9, t
        xy, yaw = actor_poses(world, t, actors[1:])
        assert np.abs(xy - [a.box(t).center[:2] for a in actors[1:]]).max() < 1e-9
        assert np.abs(yaw - [a.box(t).yaw for a in actors[1:]]).max() < 1e-12
