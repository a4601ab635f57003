"""KITTI AP R40 from the devkit's definition: the same numbers as the reference Python evaluations."""

from __future__ import annotations

import json

import numpy as np
import pytest

from generator.formats.kitti_object import KittiObject
from generator.stats.detection_kitti import DIFFICULTIES, Frame, evaluate, thresholds
from kits.kitti_kit import as_predictions, synthetic
from kits.paths import ROOT

FIXTURE = ROOT / "tests" / "stats" / "fixtures" / "kitti_reference_r40.json"


@pytest.fixture(scope="module")
def synthetic26():
    gts, dts = synthetic(seed=26, frames=24)
    return [Frame.of(g) for g in gts], [Frame.of(d) for d in dts]


def test_perturbed_detections_score_as_openpcdet_and_mmdetection3d_do(synthetic26):
    ref = json.loads(FIXTURE.read_text())
    result = evaluate(*synthetic26)
    checked = 0
    for tool in ("openpcdet", "mmdet3d"):
        for cls, metrics in ref[tool].items():
            for metric, by_level in metrics.items():
                ours = result[cls]["AOS_R40"] if metric == "aos" else result[cls]["AP_R40"][metric]
                for level, value in by_level.items():
                    assert ours[DIFFICULTIES.index(level)] == pytest.approx(value, abs=1e-6), (tool, cls, metric, level)
                    checked += 1
    assert checked == 36 + 27
    assert 0 < result["Car"]["AP_R40"]["bbox"][1] < 100   # a test that could fail: not all perfect, not all zero


def test_ground_truth_scored_as_predictions_is_perfect():
    gts, _ = synthetic(seed=5, frames=160)   # >= 40 boxes per class and level: R40 reaches every recall step
    result = evaluate([Frame.of(g) for g in gts], [Frame.of(as_predictions(g)) for g in gts])
    for cls, r in result.items():
        assert min(r["n_gt"]) >= 40, cls
        for metric in ("bbox", "bev", "3d"):
            assert r["AP_R40"][metric] == pytest.approx([100.0] * 3), (cls, metric)
        assert r["AOS_R40"] == pytest.approx([100.0] * 3)


def _car(z, dx=0.0, score=None):
    return KittiObject("Car", 0.0, 0, 0.0, (500.0, 150.0, 600.0, 250.0), (1.5, 1.7, 4.2), (dx, 1.6, z), 0.0, score)


@pytest.mark.parametrize("dx, bev", [(0.5, 100.0), (1.0, 0.0)])
def test_a_car_moved_along_its_length(dx, bev):
    """IoU of a 4.2 m car moved 0.5 m: 3.7 / 4.7 = 0.79 > 0.7, a hit; moved 1 m: 3.2 / 5.2 = 0.62, a miss
    (false positive and missed car) in BEV and 3D, while its image box is unchanged."""
    gts = [Frame.of([_car(20.0 + k)]) for k in range(50)]
    dts = [Frame.of([KittiObject("Car", -1, -1, 0.0, (500.0, 150.0, 600.0, 250.0), (1.5, 1.7, 4.2),
                                 (dx, 1.6, 20.0 + k), 0.0, 0.9)]) for k in range(50)]
    r = evaluate(gts, dts, ["Car"])["Car"]
    assert r["AP_R40"]["bev"] == pytest.approx([bev] * 3) and r["AP_R40"]["3d"] == pytest.approx([bev] * 3)
    assert r["AP_R40"]["bbox"] == pytest.approx([100.0] * 3)


def test_ignored_ground_truth_and_dontcare_cost_nothing():
    # a Van detected as a Car, a car too small for "easy", a detection inside a DontCare region
    gt = [_car(20.0)] * 1 + [KittiObject("Van", 0.0, 0, 0.0, (700.0, 150.0, 800.0, 250.0), (2.0, 1.9, 5.0),
                                         (5.0, 1.6, 20.0), 0.0),
                             KittiObject("DontCare", -1, -1, -10, (0.0, 0.0, 100.0, 100.0), (-1, -1, -1),
                                         (-1000, -1000, -1000), -10)]
    dt = [KittiObject("Car", -1, -1, 0.0, b, d, loc, 0.0, 0.9) for b, d, loc in
          [((500.0, 150.0, 600.0, 250.0), (1.5, 1.7, 4.2), (0.0, 1.6, 20.0)),
           ((700.0, 150.0, 800.0, 250.0), (2.0, 1.9, 5.0), (5.0, 1.6, 20.0)),
           ((10.0, 10.0, 60.0, 90.0), (1.5, 1.7, 4.2), (-30.0, 1.6, 20.0))]]
    r = evaluate([Frame.of(gt)] * 45, [Frame.of(dt)] * 45, ["Car"])["Car"]
    assert r["AP_R40"]["bbox"] == pytest.approx([100.0] * 3)


def test_few_boxes_reach_few_recall_steps_as_in_the_devkit():
    assert len(thresholds(np.ones(3), 3)) == 3          # 3 boxes: recall positions 0..2 of 40
    assert len(thresholds(np.linspace(1, 0, 200), 200)) == 41
