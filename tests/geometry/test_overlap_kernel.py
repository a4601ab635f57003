"""The compiled occupancy test answers exactly as the numpy separating-axis test.

A town is byte-identical only if every placement decision is the same, so the kernel
(generator/layout/overlap_kernel.py) must agree with ``placement_core.overlaps`` on every
pair -- including boxes that just touch, share an edge, or are turned by right angles, where
the float arithmetic decides.
"""

from __future__ import annotations

import numpy as np

from generator.geometry.boxes import boxes_overlap
from generator.geometry.overlap_kernel import any_overlap
from generator.layout.placement.placer import Occupancy


def _kernel(a, b):
    return any_overlap(a, np.cos(a[:, 4]), np.sin(a[:, 4]), b, np.cos(b[:, 4]), np.sin(b[:, 4]))


def _boxes(rng, n, spread, snap):
    b = np.c_[rng.uniform(-spread, spread, (n, 2)), rng.uniform(0.05, 3, (n, 2)), rng.uniform(-np.pi, np.pi, n),
              rng.uniform(0, 2, n), rng.uniform(2, 4, n)]
    if snap:  # grid-aligned centres, half sizes and right-angle yaws: touching boxes
        b[:, :4] = np.round(b[:, :4] * 4) / 4
        b[:, 2:4] = np.maximum(b[:, 2:4], 0.25)
        b[:, 4] = rng.integers(-2, 3, n) * (np.pi / 2)
    return b


def test_kernel_agrees_with_overlaps_on_random_and_touching_boxes():
    rng = np.random.default_rng(11)
    answers = {True: 0, False: 0}
    for t in range(6000):
        snap = t % 2 == 0
        a, b = _boxes(rng, int(rng.integers(1, 6)), 6.0, snap), _boxes(rng, int(rng.integers(1, 40)), 12.0, snap)
        want = bool(boxes_overlap(a, b).any())
        assert _kernel(a, b) == want, (a, b)
        answers[want] += 1
    assert min(answers.values()) > 1000  # both answers exercised


def test_kernel_agrees_pair_by_pair_at_the_boundary():
    """Two unit boxes slid along x through contact: the same verdict at every step."""
    a = np.array([[0.0, 0.0, 0.5, 0.5, 0.0, 0.0, 1.0]])
    for yaw in (0.0, np.pi / 2, np.pi / 4, 1e-9):
        for x in np.linspace(0.9, 1.1, 401):
            b = np.array([[x, 0.3, 0.5, 0.5, yaw, 0.0, 1.0]])
            assert _kernel(a, b) == bool(boxes_overlap(a, b).any()), (yaw, x)


def test_occupancy_hits_is_overlaps_of_the_boxes_near():
    rng = np.random.default_rng(12)
    occ = Occupancy()
    for _ in range(300):
        boxes = _boxes(rng, int(rng.integers(1, 4)), 40.0, bool(rng.integers(2)))
        want = len(occ.boxes) > 0 and bool(boxes_overlap(boxes, occ.boxes).any())
        assert occ.hits(boxes) == want
        if not want:
            occ.add(boxes)
    assert len(occ.boxes) > 100
