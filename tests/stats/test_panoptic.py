"""Panoptic quality as SemanticKITTI's panoptic benchmark defines it (semantic-kitti-api PanopticEval)."""

from __future__ import annotations

import numpy as np
import pytest

from generator.cli import main
from generator.formats import semantickitti as sk
from generator.labels import class_table
from generator.labels.sets import label_sets
from generator.stats.evaluate import evaluate_trees
from generator.stats.panoptic import SEMANTICKITTI_THINGS, PanopticAccumulator, thing_classes

CAR, ROAD, BUILDING = 10, 40, 50


def _scan(root, raw, inst, seq="00", index=0):
    sk.write_labels(sk.sequence_dir(root, seq) / "labels" / f"{index:06d}.label",
                    np.asarray(raw, np.uint16), np.asarray(inst, np.uint16))
    return root


def _rep(*runs):
    """Concatenate (value, count) runs."""
    return np.concatenate([np.full(n, v) for v, n in runs])


def test_kirillov_example_gives_the_published_pq():
    """The panoptic segmentation paper's toy case (ignore, grass, sky, person, dog), every segment counted.

    grass and sky: one stuff segment each, 40 of 50 points right -> IoU 2/3, PQ 2/3. A dog
    predicted as a person: a dog FN and a person FP. Three people (150, 50, 100 points), two
    predicted (200 over the first two, 100 exactly on the third): matches at IoU 3/4 and 1, the
    50-point person a FN -> SQ 7/8, RQ 2 / (2 + 1/2 + 1/2), PQ 7/12. Means over the 4 classes.
    """
    pred_c = _rep((0, 50), (1, 40), (2, 10), (2, 40), (1, 10), (3, 50), (3, 300))
    pred_i = _rep((0, 50), (0, 50), (0, 50), (35, 50), (8, 200), (95, 100))
    gt_c = _rep((0, 50), (1, 50), (2, 50), (4, 50), (3, 300))
    gt_i = _rep((0, 50), (0, 50), (0, 50), (22, 50), (33, 150), (42, 50), (11, 100))
    acc = PanopticAccumulator(5, (0,), min_points=1)
    acc.add(pred_c, pred_i, gt_c, gt_i)
    pq, sq, rq = acc.scores()
    assert pq[1:] == pytest.approx([2 / 3, 2 / 3, 7 / 12, 0.0])
    assert sq[3] == pytest.approx(0.875) and rq[3] == pytest.approx(2 / 3)
    assert pq[1:].mean() == pytest.approx(0.47916666666666663)
    assert sq[1:].mean() == pytest.approx(0.5520833333333333) and rq[1:].mean() == pytest.approx(2 / 3)


def test_small_unmatched_segments_count_nowhere(tmp_path):
    """Two cars (60 and 10 points) and road; the small car is predicted road, 5 unlabeled points predicted car.

    vehicle: the big car matches (IoU 1) whatever its predicted instance id; the 10-point car is
    no FN under min_points 50, a FN under 5 (RQ 1 / (1 + 1/2)). road: IoU 100/110 -> SQ 10/11.
    Ground-truth-unlabeled points are dropped before matching.
    """
    gt = _scan(tmp_path / "gt", _rep((CAR, 60), (CAR, 10), (ROAD, 100), (0, 5)), _rep((1, 60), (2, 10), (0, 105)))
    pred = _scan(tmp_path / "pred", _rep((CAR, 60), (ROAD, 10), (ROAD, 100), (CAR, 5)), _rep((7, 60), (0, 110), (7, 5)))
    res = evaluate_trees(pred, gt, "unified11", progress=False, mean_over="present", panoptic=True)["panoptic"]
    cls = {c["name"]: c for c in res["classes"] if c["in_mean"]}
    assert set(cls) == {"vehicle", "road"}
    assert (cls["vehicle"]["tp"], cls["vehicle"]["fp"], cls["vehicle"]["fn"], cls["vehicle"]["pq"]) == (1, 0, 0, 1.0)
    assert cls["road"]["sq"] == pytest.approx(10 / 11) and cls["road"]["rq"] == 1.0 and not cls["road"]["thing"]
    assert res["pq"] == pytest.approx((1 + 10 / 11) / 2) and res["pq_things"] == 1.0
    assert res["pq_dagger"] == pytest.approx((1 + cls["road"]["iou"]) / 2)
    strict = evaluate_trees(pred, gt, "unified11", progress=False, mean_over="present", panoptic=True,
                            min_points=5)["panoptic"]
    vehicle = next(c for c in strict["classes"] if c["name"] == "vehicle")
    assert vehicle["fn"] == 1 and vehicle["pq"] == pytest.approx(2 / 3)


def test_a_set_against_itself_has_pq_1(tmp_path, rng):
    """Two scans with cars, people (instances) and stuff of several raw ids: every segment matches itself."""
    for i in range(2):
        raw = rng.choice([CAR, 30, ROAD, 60, BUILDING, 70], 3000)
        inst = np.where(np.isin(raw, [CAR, 30]), rng.integers(1, 6, 3000), 0)
        _scan(tmp_path / "gt", raw, inst, index=i)
    for labels in ("unified11", "semantickitti"):
        res = evaluate_trees(tmp_path / "gt", tmp_path / "gt", labels, progress=False, mean_over="present",
                             panoptic=True)["panoptic"]
        assert res["pq"] == res["sq"] == res["rq"] == 1.0
        assert all(c["fp"] == c["fn"] == 0 for c in res["classes"])
        ref = evaluate_trees(tmp_path / "gt", tmp_path / "gt", labels, progress=False, panoptic=True)["panoptic"]
        n_present = sum(c["tp"] > 0 for c in ref["classes"])
        assert ref["pq"] == pytest.approx(n_present / (len(label_sets()[labels].names) - 1))  # absent classes as 0


def test_thing_classes_follow_the_reference_and_the_class_table():
    sets = label_sets()
    sk_things = [n for n, t in zip(sets["semantickitti"].names, thing_classes(sets["semantickitti"]), strict=False)
                 if t]
    assert sorted(sk_things) == sorted(SEMANTICKITTI_THINGS)
    uni = [n for n, t in zip(sets["unified11"].names, thing_classes(sets["unified11"]), strict=False) if t]
    assert uni == ["vehicle", "person"]
    nat = [n for n, t in zip(sets["native"].names, thing_classes(sets["native"]), strict=False) if t]
    assert nat == [r.name for r in class_table().rows if r.thing]
    assert {"car", "truck", "person", "bicycle", "motorcycle", "bus", "bicyclist", "motorcyclist"} <= set(nat)


def test_cli_panoptic_prints_pq(tmp_path, capsys):
    gt = _scan(tmp_path / "gt", _rep((CAR, 60), (ROAD, 60)), _rep((3, 60), (0, 60)))
    assert main(["eval", "--pred", str(gt), "--gt", str(gt), "--panoptic", "--mean-over", "present",
                 "--json", str(tmp_path / "r.json")]) == 0
    out = capsys.readouterr().out
    assert "PQ 100.00" in out and "vehicle" in out and "thing" in out
