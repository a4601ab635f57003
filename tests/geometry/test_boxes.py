"""Production's box overlap (generator/geometry/boxes.py) agrees with the traffic tests' contact kit.

The kit (tests/kits/traffic_contacts.py) judges the simulation with its own footprints and
shapely's polygon intersection, so that a wrong separating-axis test cannot pass the traffic
tests; here both are held to each other: on many random boxes (near misses and touching pairs
included), and on hand-made cases whose answer is known.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from generator.geometry.boxes import OrientedBox, boxes_overlap, quads_overlap
from kits.traffic_contacts import Box, footprint, footprints, touching


def _random_boxes(rng, n: int, spread: float) -> list[Box]:
    xy = rng.uniform(-spread, spread, (n, 2))
    size = rng.uniform([0.3, 0.3], [12.0, 3.0], (n, 2))
    yaw = rng.uniform(-np.pi, np.pi, n)
    return [Box((x, y, 0.75), (length, width, 1.5), h)
            for (x, y), (length, width), h in zip(xy, size, yaw, strict=True)]


def _production_quads(boxes) -> np.ndarray:
    return np.stack([OrientedBox(b.center, b.size, b.yaw).corners_xy() for b in boxes])


def test_the_kit_footprint_is_the_production_footprint():
    rng = np.random.default_rng(0)
    boxes = _random_boxes(rng, 500, 50.0)
    kit, prod = footprints(boxes), _production_quads(boxes)
    # the same four corners (production may start at another one) and the same area
    for k, p in zip(kit, prod, strict=True):
        assert min(np.abs(np.roll(k, r, axis=0) - p).max() for r in range(4)) < 1e-9
    assert np.allclose(shapely.area(shapely.polygons(kit)), [b.size[0] * b.size[1] for b in boxes])


@pytest.mark.parametrize("seed, spread", [(1, 6.0), (2, 12.0), (3, 25.0)])
def test_production_overlap_agrees_with_polygon_intersection_on_random_boxes(seed, spread):
    """400 x 400 random pairs per case, some thousands of them overlapping: the quad and the
    box-row tests of production say what shapely says, except where the two footprints are closer
    than a micrometre to touching (floating point decides those either way)."""
    rng = np.random.default_rng(seed)
    a, b = _random_boxes(rng, 400, spread), _random_boxes(rng, 400, spread)
    qa, qb = footprints(a), footprints(b)
    kit = touching(qa, qb)
    quads = quads_overlap(_production_quads(a), _production_quads(b))
    rows = boxes_overlap(np.concatenate([o.row() for o in map(lambda x: OrientedBox(x.center, x.size, x.yaw), a)]),
                         np.concatenate([o.row() for o in map(lambda x: OrientedBox(x.center, x.size, x.yaw), b)]))
    assert 1000 < kit.sum() < kit.size - 1000          # both answers occur often
    pa, pb = shapely.polygons(qa), shapely.polygons(qb)
    for prod in (quads, rows):
        i, j = np.nonzero(prod != kit)
        gap = shapely.distance(pa[i], pb[j])
        depth = shapely.area(shapely.intersection(pa[i], pb[j]))
        assert (np.maximum(gap, depth) < 1e-6).all(), list(zip(i[:3], j[:3], strict=True))


# (a, b, overlap?): the cases a plausible wrong test gets wrong
CASES = [
    # a plus sign: no corner of either box lies inside the other (a corner-in-polygon test says no)
    (Box((0, 0, 0), (10.0, 1.0, 1), 0.0), Box((0, 0, 0), (10.0, 1.0, 1), np.pi / 2), True),
    # a thin box diagonally past a corner: the first box's axes overlap, only the second's separate
    (Box((0, 0, 0), (4.0, 4.0, 1), 0.0), Box((3.3, 3.3, 0), (6.0, 0.4, 1), -np.pi / 4), False),
    # the same thin box pushed in: now they overlap
    (Box((0, 0, 0), (4.0, 4.0, 1), 0.0), Box((2.1, 2.1, 0), (6.0, 0.4, 1), -np.pi / 4), True),
    # edge to edge: touching counts as contact
    (Box((0, 0, 0), (4.0, 2.0, 1), 0.0), Box((4.0, 0, 0), (4.0, 2.0, 1), 0.0), True),
    # a centimetre apart
    (Box((0, 0, 0), (4.0, 2.0, 1), 0.0), Box((4.01, 0, 0), (4.0, 2.0, 1), 0.0), False),
    # one inside the other
    (Box((0, 0, 0), (8.0, 4.0, 1), 0.3), Box((0.5, 0.2, 0), (1.0, 0.5, 1), 1.2), True),
]


@pytest.mark.parametrize("a, b, want", CASES)
def test_both_give_the_known_answer(a, b, want):
    assert touching(footprint(a)[None], footprint(b)[None])[0, 0] == want
    assert touching(footprint(b)[None], footprint(a)[None])[0, 0] == want
    assert quads_overlap(_production_quads([a]), _production_quads([b]))[0, 0] == want
