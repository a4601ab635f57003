"""IoU / mIoU evaluation of two SemanticKITTI label trees (seed 000 Eq. 11-12)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from generator.cli import main
from generator.errors import UserError
from generator.formats import semantickitti as sk
from generator.formats.point_sidecars import write_point_sidecars
from generator.stats.evaluate import confusion, evaluate_trees, iou_from_confusion

CAR, ROAD, BUILDING, SIDEWALK = 10, 40, 50, 48


def _write(root, seq: str, index: int, raw: np.ndarray, native: np.ndarray | None = None) -> None:
    d = sk.sequence_dir(root, seq)
    sk.write_labels(d / "labels" / f"{index:06d}.label", raw.astype(np.uint16), np.zeros(len(raw), np.uint16))
    if native is not None:
        write_point_sidecars(d, f"{index:06d}", np.zeros(len(raw)), native)


def _tree(root, scans: dict[tuple[str, int], np.ndarray], native: dict | None = None):
    for (seq, i), raw in scans.items():
        _write(root, seq, i, raw, None if native is None else native[seq, i])
    return root


@pytest.fixture
def constructed(tmp_path):
    """Ground truth and prediction over two sequences, counts chosen so the IoUs are known by hand.

    car: 10 gt points, 8 predicted car, 2 predicted road; road: 5 gt, 4 road, 1 car;
    building: 6 gt, 5 building, 1 predicted unlabeled (ignored); 3 gt-unlabeled points
    predicted building (ignored).
    """
    gt_a = np.array([CAR] * 10 + [ROAD] * 5)
    pr_a = np.array([CAR] * 8 + [ROAD] * 2 + [ROAD] * 4 + [CAR])
    gt_b = np.array([BUILDING] * 6 + [0] * 3)
    pr_b = np.array([BUILDING] * 5 + [0] + [BUILDING] * 3)
    gt = _tree(tmp_path / "gt", {("00", 0): gt_a, ("01", 0): gt_b})
    pred = _tree(tmp_path / "pred", {("00", 0): pr_a, ("01", 0): pr_b})
    return pred, gt


def test_constructed_confusion_gives_hand_computed_ious(constructed):
    pred, gt = constructed
    res = evaluate_trees(pred, gt, "unified11", progress=False)
    iou = {c["name"]: c["iou"] for c in res["classes"] if c["status"] == "evaluated"}
    # vehicle: TP 8, FP 1, FN 2 -> 8/11; road: TP 4, FP 2, FN 1 -> 4/7; building: TP 5, FP 0, FN 0 -> 1
    assert iou == pytest.approx({"vehicle": 8 / 11, "road": 4 / 7, "building": 1.0})
    assert res["miou"] == pytest.approx((8 / 11 + 4 / 7 + 1.0) / 3)
    assert res["evaluated_classes"] == 3
    assert "person" in res["absent_classes"] and "unlabeled" not in res["absent_classes"]
    assert res["scans"] == 2 and res["points"] == 24 and res["points_evaluated"] == 20  # 4 ignored
    # the SemanticKITTI learning classes give the same numbers for these raw ids
    sk19 = evaluate_trees(pred, gt, "semantickitti", progress=False)
    assert sk19["miou"] == pytest.approx(res["miou"])


def test_identical_trees_give_100_percent(constructed, tmp_path):
    _, gt = constructed
    for labels in ("unified11", "semantickitti"):
        res = evaluate_trees(gt, gt, labels, progress=False)
        assert res["miou"] == 1.0 and res["accuracy"] == 1.0
        assert all(c["iou"] == 1.0 for c in res["classes"] if c["status"] == "evaluated")
    # native classes come from the side files: road_marking (2) and crosswalk (3) share raw id 60
    raw = np.array([60, 60, 60, 40])
    native = np.array([2, 3, 3, 1], np.uint8)
    a = _tree(tmp_path / "na", {("00", 0): raw}, {("00", 0): native})
    b = _tree(tmp_path / "nb", {("00", 0): raw}, {("00", 0): np.array([2, 2, 3, 1], np.uint8)})
    assert evaluate_trees(a, a, "native", progress=False)["miou"] == 1.0
    assert evaluate_trees(a, a, "unified11", progress=False)["miou"] == 1.0
    res = evaluate_trees(b, a, "native", progress=False)  # one crosswalk point predicted road_marking
    iou = {c["name"]: c["iou"] for c in res["classes"] if c["status"] == "evaluated"}
    assert iou == pytest.approx({"road": 1.0, "road_marking": 1 / 2, "crosswalk": 1 / 2})


def test_confusion_matches_a_loop(rng):
    gt = rng.integers(0, 6, 500)
    pred = rng.integers(0, 6, 500)
    c = confusion(gt, pred, 6)
    loop = np.zeros((6, 6), np.int64)
    for g, p in zip(gt, pred):
        loop[g, p] += 1
    assert np.array_equal(c, loop)
    res = iou_from_confusion(c)
    assert np.isnan(res.iou[0]) and not res.evaluated[0]


def test_mismatched_trees_are_user_errors(constructed, tmp_path):
    pred, gt = constructed
    _write(pred, "00", 0, np.array([CAR] * 3))
    with pytest.raises(UserError, match="labels but the ground truth has"):
        evaluate_trees(pred, gt, progress=False)
    with pytest.raises(UserError, match="missing"):
        evaluate_trees(tmp_path / "gt", _tree(tmp_path / "g2", {("00", 5): np.array([CAR])}), progress=False)
    with pytest.raises(UserError, match="native_labels"):
        evaluate_trees(gt, gt, "native", progress=False)


def test_cli_prints_table_and_writes_json(constructed, tmp_path, capsys):
    pred, gt = constructed
    out = tmp_path / "res.json"
    assert main(["eval", "--pred", str(pred), "--gt", str(gt), "--json", str(out)]) == 0
    text = capsys.readouterr().out
    assert "vehicle" in text and "mIoU" in text and "left out of the mean" in text
    assert json.loads(out.read_text())["miou"] == pytest.approx((8 / 11 + 4 / 7 + 1.0) / 3)
    assert main(["eval", "--pred", str(tmp_path / "nope"), "--gt", str(gt)]) == 2
    with pytest.raises(SystemExit) as e:
        main(["eval", "--pred", str(pred), "--gt", str(gt), "--labels", "bogus"])
    assert e.value.code == 2
