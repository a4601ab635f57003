"""IoU / mIoU (and PQ) of two SemanticKITTI label trees, computed as semantic-kitti-api does."""

from __future__ import annotations

import json

import numpy as np
import pytest

from generator.cli import build_parser, main
from generator.errors import UserError
from generator.formats import semantickitti as sk
from generator.formats.point_sidecars import write_point_sidecars
from generator.labels.sets import label_sets
from generator.stats.evaluate import confusion, evaluate_trees, iou_from_confusion

CAR, ROAD, BUILDING, SIDEWALK = 10, 40, 50, 48


def _write(root, seq: str, index: int, raw: np.ndarray, native: np.ndarray | None = None,
           instance: np.ndarray | None = None, folder: str = "labels") -> None:
    d = sk.sequence_dir(root, seq)
    inst = np.zeros(len(raw), np.uint16) if instance is None else instance.astype(np.uint16)
    sk.write_labels(d / folder / f"{index:06d}.label", raw.astype(np.uint16), inst)
    if native is not None:
        write_point_sidecars(d, f"{index:06d}", np.zeros(len(raw)), native)


def _tree(root, scans: dict[tuple[str, int], np.ndarray], native: dict | None = None, folder: str = "labels"):
    for (seq, i), raw in scans.items():
        _write(root, seq, i, raw, None if native is None else native[seq, i], folder=folder)
    return root


@pytest.fixture
def constructed(tmp_path):
    """Ground truth and prediction over two sequences, counts chosen so the IoUs are known by hand.

    car: 10 gt points, 8 predicted car, 2 predicted road; road: 5 gt, 4 road, 1 car;
    building: 6 gt, 5 building, 1 predicted unlabeled (a false negative, as the reference
    counts it); 3 gt-unlabeled points predicted building (ignored: gt 0 counts nowhere).
    """
    gt_a = np.array([CAR] * 10 + [ROAD] * 5)
    pr_a = np.array([CAR] * 8 + [ROAD] * 2 + [ROAD] * 4 + [CAR])
    gt_b = np.array([BUILDING] * 6 + [0] * 3)
    pr_b = np.array([BUILDING] * 5 + [0] + [BUILDING] * 3)
    gt = _tree(tmp_path / "gt", {("00", 0): gt_a, ("01", 0): gt_b})
    pred = _tree(tmp_path / "pred", {("00", 0): pr_a, ("01", 0): pr_b})
    return pred, gt


# vehicle: TP 8, FP 1, FN 2; road: TP 4, FP 2, FN 1; building: TP 5, FP 0, FN 1 (the point predicted 0)
HAND = {"vehicle": 8 / 11, "road": 4 / 7, "building": 5 / 6}


def test_a_labelled_point_predicted_0_is_a_false_negative(tmp_path):
    """The issue's case: 6 building points, one predicted 0 -> IoU 5/6, as np_ioueval gives."""
    gt = _tree(tmp_path / "gt", {("00", 0): np.array([BUILDING] * 6)})
    pred = _tree(tmp_path / "pred", {("00", 0): np.array([BUILDING] * 5 + [0])})
    res = evaluate_trees(pred, gt, "unified11", progress=False, mean_over="present")
    building = next(c for c in res["classes"] if c["name"] == "building")
    assert building["iou"] == pytest.approx(5 / 6) and (building["tp"], building["fp"], building["fn"]) == (5, 0, 1)
    assert res["miou"] == pytest.approx(0.8333, abs=1e-4)


def test_constructed_confusion_gives_hand_computed_ious(constructed):
    pred, gt = constructed
    res = evaluate_trees(pred, gt, "unified11", progress=False)
    iou = {c["name"]: c["iou"] for c in res["classes"] if c["status"] == "present"}
    assert iou == pytest.approx(HAND)
    # the reference averages every non-ignored class of the set: 11 in unified11, absent ones as 0
    assert res["mean_over"] == "all" and res["evaluated_classes"] == 11
    assert res["miou"] == pytest.approx(sum(HAND.values()) / 11)
    assert "person" in res["absent_classes"] and "unlabeled" not in res["absent_classes"]
    # accuracy as the reference: TP / (TP + FP) of the non-ignored classes; the point predicted 0 is in neither
    assert res["accuracy"] == pytest.approx(17 / 20)
    assert res["scans"] == 2 and res["points"] == 24 and res["points_evaluated"] == 21  # 3 gt-unlabeled
    present = evaluate_trees(pred, gt, "unified11", progress=False, mean_over="present")
    assert present["miou"] == pytest.approx(sum(HAND.values()) / 3) and present["evaluated_classes"] == 3
    # the SemanticKITTI learning classes: same per-class numbers, mean over its 19 classes
    sk19 = evaluate_trees(pred, gt, "semantickitti", progress=False)
    assert sk19["evaluated_classes"] == 19 and sk19["miou"] == pytest.approx(sum(HAND.values()) / 19)


def test_iou_matches_the_definition_on_random_labels(rng):
    """Against a per-point count of the reference definition (gt 0 ignored, pred 0 kept)."""
    n = 7
    gt, pred = rng.integers(0, n, 2000), rng.integers(0, n, 2000)
    c = confusion(pred, gt, n)
    loop = np.zeros((n, n), np.int64)
    for g, p in zip(gt, pred, strict=False):
        loop[p, g] += 1
    assert np.array_equal(c, loop)
    res = iou_from_confusion(c, mean_over="all")
    for k in range(1, n):
        tp = np.sum((pred == k) & (gt == k))
        fp = np.sum((pred == k) & (gt != k) & (gt != 0))
        fn = np.sum((gt == k) & (pred != k))
        assert (res.tp[k], res.fp[k], res.fn[k]) == (tp, fp, fn)
        assert res.iou[k] == pytest.approx(tp / (tp + fp + fn))
    assert np.isnan(res.iou[0]) and not res.evaluated[0]
    assert res.miou == pytest.approx(np.mean(res.iou[1:]))


def test_identical_trees_score_1_on_every_present_class(constructed, tmp_path):
    _, gt = constructed
    for labels in ("unified11", "semantickitti"):
        res = evaluate_trees(gt, gt, labels, progress=False, mean_over="present")
        assert res["miou"] == 1.0 and res["accuracy"] == 1.0
        assert all(c["iou"] == 1.0 for c in res["classes"] if c["status"] == "present")
        ref = evaluate_trees(gt, gt, labels, progress=False)  # absent classes pull the reference mean down
        assert ref["miou"] == pytest.approx(3 / ref["evaluated_classes"])
    # native classes come from the side files: road_marking (2) and crosswalk (3) share raw id 60
    raw = np.array([60, 60, 60, 40])
    native = np.array([2, 3, 3, 1], np.uint8)
    a = _tree(tmp_path / "na", {("00", 0): raw}, {("00", 0): native})
    b = _tree(tmp_path / "nb", {("00", 0): raw}, {("00", 0): np.array([2, 2, 3, 1], np.uint8)})
    assert evaluate_trees(a, a, "native", progress=False, mean_over="present")["miou"] == 1.0
    assert evaluate_trees(a, a, "unified11", progress=False, mean_over="present")["miou"] == 1.0
    res = evaluate_trees(b, a, "native", progress=False)  # one crosswalk point predicted road_marking
    iou = {c["name"]: c["iou"] for c in res["classes"] if c["status"] == "present"}
    assert iou == pytest.approx({"road": 1.0, "road_marking": 1 / 2, "crosswalk": 1 / 2})


def test_predictions_folder_of_the_reference_layout_is_read(constructed, tmp_path):
    """semantic-kitti-api reads PRED/sequences/NN/predictions/; so do we, when it exists."""
    pred, gt = constructed
    other = tmp_path / "p2"
    for seq in ("00", "01"):
        src = sk.sequence_dir(pred, seq) / "labels" / "000000.label"
        dst = sk.sequence_dir(other, seq) / "predictions" / "000000.label"
        dst.parent.mkdir(parents=True)
        dst.write_bytes(src.read_bytes())
    assert evaluate_trees(other, gt, progress=False)["miou"] == evaluate_trees(pred, gt, progress=False)["miou"]


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
    assert "vehicle" in text and "mIoU" in text and "counted as IoU 0" in text and "83.33" in text
    assert json.loads(out.read_text())["miou"] == pytest.approx(sum(HAND.values()) / 11)
    assert main(["eval", "--pred", str(tmp_path / "nope"), "--gt", str(gt)]) == 2
    assert main(["eval", "--pred", str(pred), "--gt", str(gt), "--panoptic", "--min-points", "0"]) == 2
    for bad in (["--labels", "bogus"], ["--mean-over", "some"]):  # argparse's errors: main returns 2 too
        assert main(["eval", "--pred", str(pred), "--gt", str(gt), *bad]) == 2


def test_help_says_which_classes_are_averaged():
    sub = next(a for a in build_parser()._actions if a.dest == "command")
    text = sub.choices["eval"].format_help()
    n = {name: len(ls.names) - 1 for name, ls in label_sets().items()}
    assert f"{n['unified11']} classes for unified11" in " ".join(text.split())
    assert f"{n['semantickitti']} for semantickitti" in " ".join(text.split())
    assert "absent" in text and "counts as IoU 0" in " ".join(text.split())
