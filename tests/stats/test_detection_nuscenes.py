"""nuScenes detection metrics through nuscenes-devkit: ground truth scores 1, hand cases give the numbers the
devkit's definitions give, and any perturbation gives exactly what DetectionEval run directly gives."""

from __future__ import annotations

import copy
import json

import numpy as np
import pytest

from generator.stats import detection_nuscenes as dn

pytest.importorskip("nuscenes")


@pytest.fixture(scope="module")
def gt_preds(nuscenes_traffic):
    return dn.ground_truth_predictions(nuscenes_traffic)


def _write(tmp_path, preds, name="pred.json"):
    p = tmp_path / name
    p.write_text(json.dumps(preds))
    return p


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    """A hand-made dataroot whose boxes lie far apart (kits.detection_data.tiny_nuscenes) and its ground truth."""
    from kits.detection_data import tiny_nuscenes

    root = tiny_nuscenes(tmp_path_factory.mktemp("tiny") / "nus")
    return root, dn.ground_truth_predictions(root)


def _moved(preds, metres: float, which=None) -> dict:
    """Boxes (all, or the ``which``-th of each sample) moved ``metres`` along +x."""
    out = copy.deepcopy(preds)
    for boxes in out["results"].values():
        for k, b in enumerate(boxes):
            if which is None or k == which:
                b["translation"][0] += metres
    return out


def test_ground_truth_as_predictions_scores_map_1_and_nds_1(nuscenes_traffic, gt_preds, tmp_path):
    r = dn.evaluate(_write(tmp_path, gt_preds), nuscenes_traffic)
    assert {"car", "truck", "pedestrian"} <= set(r["classes"])      # classes with a box within their range
    assert r["mAP"] == pytest.approx(1.0, abs=1e-12) and r["NDS"] == pytest.approx(1.0, abs=1e-12)
    assert all(v == pytest.approx(0.0, abs=1e-12) for v in r["tp_errors"].values())
    assert all(ap == pytest.approx(1.0, abs=1e-12) for c in r["per_class"].values() for ap in c["AP"].values())


def test_boxes_1_5_m_off_are_hits_at_2_and_4_m_only(tiny, tmp_path):
    """AP 0, 0, 1, 1 at 0.5, 1, 2, 4 m: mAP 0.5; ATE 1.5 m, the rest 0: NDS = (5 * 0.5 + 0 + 4) / 10."""
    root, gt = tiny
    r = dn.evaluate(_write(tmp_path, _moved(gt, 1.5)), root)
    assert r["classes"] == ["car", "pedestrian"]
    for c in r["per_class"].values():
        assert c["AP"] == pytest.approx({"0.5": 0.0, "1.0": 0.0, "2.0": 1.0, "4.0": 1.0}, abs=1e-12)
        assert c["mATE"] == pytest.approx(1.5, abs=1e-9)
    assert r["mAP"] == pytest.approx(0.5) and r["NDS"] == pytest.approx(0.65)


def test_boxes_3_m_off_are_hits_at_4_m_only_and_no_true_positive_is_left_at_2_m(tiny, tmp_path):
    """mAP 0.25; at the TP threshold (2 m) nothing matches, so every TP error is 1: NDS = 5 * 0.25 / 10."""
    root, gt = tiny
    r = dn.evaluate(_write(tmp_path, _moved(gt, 3.0)), root)
    assert r["mAP"] == pytest.approx(0.25) and r["NDS"] == pytest.approx(0.125)
    assert all(v == pytest.approx(1.0, abs=1e-12) for v in r["tp_errors"].values())


def test_one_car_moved_by_1_m_is_a_true_positive_at_2_m_not_at_0_5_m(tiny, tmp_path):
    """12 cars (4 per key frame), the first of the first sample moved 1 m and scored lowest: at 0.5 and 1 m it
    is a false positive after 11 hits, so precision is 1 up to recall 11/12 and nothing after: the devkit's AP
    (recall 0.11..1.00 in 90 steps, precision above 0.1 rescaled) is 81/90 = 0.9; at 2 and 4 m it is a hit."""
    root, gt = tiny
    preds = copy.deepcopy(gt)
    first = next(iter(preds["results"]))
    car = next(k for k, b in enumerate(preds["results"][first]) if b["detection_name"] == "car")
    preds["results"][first][car]["translation"][0] += 1.0
    preds["results"][first][car]["detection_score"] = 0.5
    r = dn.evaluate(_write(tmp_path, preds), root)
    car = r["per_class"]["car"]
    assert car["AP"] == pytest.approx({"0.5": 0.9, "1.0": 0.9, "2.0": 1.0, "4.0": 1.0}, abs=1e-12)
    assert 0 < car["mATE"] < 0.1
    assert r["per_class"]["pedestrian"]["mean_AP"] == pytest.approx(1.0, abs=1e-12)


def test_perturbed_predictions_give_the_devkits_own_numbers(nuscenes_traffic, gt_preds, tmp_path):
    """Noise, scores, dropped boxes and false positives: our result is what DetectionEval computes directly."""
    from nuscenes import NuScenes
    from nuscenes.eval.common.config import config_factory
    from nuscenes.eval.detection.evaluate import DetectionEval

    rng = np.random.default_rng(3)
    preds = copy.deepcopy(gt_preds)
    for tok, boxes in preds["results"].items():
        keep = []
        for b in boxes:
            if rng.random() < 0.15:
                continue
            b["translation"] = (np.array(b["translation"]) + rng.normal(0, 0.4, 3)).tolist()
            b["size"] = (np.array(b["size"]) * rng.uniform(0.8, 1.2, 3)).tolist()
            yaw = rng.normal(0, 0.3)
            q = np.array(b["rotation"])
            b["rotation"] = (q * np.cos(yaw / 2) + np.array([-q[3], -q[2], q[1], q[0]]) * np.sin(yaw / 2)).tolist()
            b["velocity"] = (np.array(b["velocity"]) + rng.normal(0, 0.5, 2)).tolist()
            b["detection_score"] = float(rng.uniform(0.2, 1.0))
            keep.append(b)
        fp = copy.deepcopy(boxes[0]) if boxes else None
        if fp is not None:
            fp["translation"][0] += 15.0
            fp["detection_score"] = float(rng.uniform(0, 0.6))
            keep.append(fp)
        preds["results"][tok] = keep
    path = _write(tmp_path, preds)
    ours = dn.evaluate(path, nuscenes_traffic)
    assert 0.2 < ours["mAP"] < 0.95 and 0.2 < ours["NDS"] < 0.95

    nusc = NuScenes(version="v1.0-urbangen", dataroot=str(nuscenes_traffic), verbose=False)
    cfg = config_factory("detection_cvpr_2019")
    cfg.class_names = ours["classes"]
    metrics, _ = DetectionEval(nusc, cfg, str(path), "urbangen_val", str(tmp_path / "direct"), verbose=False).evaluate()
    direct = metrics.serialize()
    assert ours["mAP"] == direct["mean_ap"] and ours["NDS"] == direct["nd_score"]
    for c in ours["classes"]:
        assert ours["per_class"][c]["AP"] == {str(d): v for d, v in direct["label_aps"][c].items()}
        for ours_name, theirs in (("mATE", "trans_err"), ("mASE", "scale_err"), ("mAOE", "orient_err"),
                                  ("mAVE", "vel_err"), ("mAAE", "attr_err")):
            a, b = ours["per_class"][c][ours_name], direct["label_tp_errors"][c][theirs]
            assert (a is None and np.isnan(b)) or a == b


def test_all_ten_classes_on_request_and_an_empty_submission(nuscenes_traffic, gt_preds, tmp_path):
    r = dn.evaluate(_write(tmp_path, gt_preds), nuscenes_traffic, classes="all")
    assert len(r["classes"]) == 10 and r["mAP"] < 0.5                # classes never drawn score 0
    empty = {"meta": gt_preds["meta"], "results": {t: [] for t in gt_preds["results"]}}
    r = dn.evaluate(_write(tmp_path, empty, "empty.json"), nuscenes_traffic)
    assert r["mAP"] == 0.0 and r["NDS"] == 0.0 and r["predicted_boxes"] == 0
