"""The class-mix statistics: LiDAR distribution beside SemanticKITTI's, TV distance, class coverage."""

from __future__ import annotations

import numpy as np
import pytest

from generator.formats import semantickitti as sk
from generator.labels import class_table
from generator.stats.class_mix import count_points, distribution, reference_distribution, tv_distance


def test_reference_distribution_is_semantickitti_content_over_the_19_classes():
    q = reference_distribution()
    assert q[0] == 0 and q.sum() == pytest.approx(1.0)
    assert q[9] == pytest.approx(0.2055, abs=0.005)  # road: ~20.5 % of labelled points in SemanticKITTI
    assert q[15] == pytest.approx(0.275, abs=0.01)   # vegetation ~27.5 %


def test_tv_distance_bounds():
    q = reference_distribution()
    assert tv_distance(q, q) == 0.0
    one = np.zeros(20)
    one[1] = 1.0
    assert tv_distance(one, q) == pytest.approx(1.0 - q[1])


def test_scans_drawn_from_the_reference_mix_are_close_to_it(tmp_path, rng):
    """Labels sampled with SemanticKITTI's own content land within sampling noise of TV 0."""
    cfg = class_table().sk_config
    raw = np.array([int(k) for k in cfg["content"]])
    share = np.array([float(v) for v in cfg["content"].values()])
    seq = tmp_path / "sequences" / "00"
    for k in range(3):
        sem = rng.choice(raw, size=40_000, p=share / share.sum()).astype(np.uint16)
        sk.write_scan(seq / "velodyne" / f"{k:06d}.bin", np.zeros((len(sem), 3), np.float32), np.zeros(len(sem),
                                                                                                       np.float32))
        sk.write_labels(seq / "labels" / f"{k:06d}.label", sem, np.zeros(len(sem), np.uint16))
    counts, scans = count_points(tmp_path)
    assert scans == 3 and counts.sum() == 120_000
    assert tv_distance(distribution(counts), reference_distribution()) < 0.02
