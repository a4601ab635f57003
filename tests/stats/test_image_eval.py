"""``eval --images``: the numbers cityscapesScripts gives on the same files, per image, seed 001's table."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest
from PIL import Image

import generator.cli as cli
from generator.stats.image_eval import AVG_CLASS_SIZE, PixelEvaluator
from kits.label_images import perturb, write_dataset_images

FRAMES = (0, 1, 2)


@pytest.fixture(autouse=True)
def only_two_commands(monkeypatch):
    monkeypatch.setattr(cli, "COMMANDS", ["export", "eval"])


@pytest.fixture(scope="module")
def perturbed(tmp_path_factory):
    """A dataset, its Cityscapes export, and perturbed predictions named the way cityscapesScripts finds them."""
    root = tmp_path_factory.mktemp("img_eval")
    ds, export, pred = root / "ds", root / "cs", root / "pred"
    write_dataset_images(ds, FRAMES, sequence="04")
    assert cli.main(["export", "cityscapes", str(ds), str(export)]) == 0
    for k, lab in enumerate(sorted(export.glob("gtFine/val/*/*_gtFine_labelIds.png"))):
        stem = lab.name.replace("_gtFine_labelIds.png", "")
        sub = pred / ("a" if k % 2 else "b")  # any depth, as the script walks the folder
        sub.mkdir(parents=True, exist_ok=True)
        Image.fromarray(perturb(np.array(Image.open(lab)), k)).save(sub / f"{stem}_leftImg8bit_pred.png")
    return ds, export, pred


@pytest.fixture(scope="module")
def reference(perturbed, tmp_path_factory):
    """cityscapesScripts' own result JSON on the export and the predictions."""
    pytest.importorskip("cityscapesscripts")
    _, export, pred = perturbed
    report = tmp_path_factory.mktemp("cs_report")
    env = {**os.environ, "CITYSCAPES_DATASET": str(export), "CITYSCAPES_RESULTS": str(pred),
           "CITYSCAPES_EXPORT_DIR": str(report)}
    run = subprocess.run([sys.executable, "-m", "cityscapesscripts.evaluation.evalPixelLevelSemanticLabeling"],
                         env=env, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-2000:]
    return json.loads((report / "resultPixelLevelSemanticLabeling.json").read_text())


def _ours(pred, gt, out) -> dict:
    assert cli.main(["eval", "--images", "--pred", str(pred), "--gt", str(gt), "--json", str(out)]) == 0
    return json.loads(out.read_text())


def _same(ours: dict, theirs: dict, key: str, rel: float = 0.0) -> None:
    for name, v in theirs[key].items():
        mine = ours[key][name]
        if v != v:  # NaN: the class is nowhere
            assert mine is None, (key, name)
        else:
            assert mine == pytest.approx(v, rel=rel, abs=0), (key, name, mine, v)


@pytest.mark.parametrize("gt_kind", ["export", "dataset"])
def test_eval_images_gives_cityscapesscripts_numbers_on_a_perturbed_set(perturbed, reference, gt_kind, tmp_path):
    ds, export, pred = perturbed
    ours = _ours(pred, export if gt_kind == "export" else ds, tmp_path / "ours.json")
    assert ours["images"] == 2 * len(FRAMES) and not ours["ground_truth_without_prediction"]
    # the perturbation leaves scores well inside (0, 1): a comparison that can fail
    assert 0.3 < reference["averageScoreClasses"] < 0.95
    _same(ours, reference, "classScores")  # bit-identical: the same integers divided
    _same(ours, reference, "categoryScores")
    assert ours["averageScoreClasses"] == reference["averageScoreClasses"]
    assert ours["averageScoreCategories"] == reference["averageScoreCategories"]
    # iIoU sums floats image by image; the script's order is the file system's
    _same(ours, reference, "classInstScores", rel=1e-12)
    _same(ours, reference, "categoryInstScores", rel=1e-12)
    assert ours["averageScoreInstClasses"] == pytest.approx(reference["averageScoreInstClasses"], rel=1e-12)
    assert np.array_equal(ours["confMatrix_gt_pred"], np.array(reference["confMatrix"], np.int64)[:34, :34])


def test_iiou_weights_are_cityscapesscripts_own():
    mod = pytest.importorskip("cityscapesscripts.evaluation.evalPixelLevelSemanticLabeling")
    assert mod.args.avgClassSize == AVG_CLASS_SIZE


def test_per_image_scores_and_seed001_table_by_hand():
    """Two 1 x 10 images: IoU per image, the pooled IoU, and seed 001's mean of per-image IoUs."""
    ev = PixelEvaluator()
    road, sidewalk, car, static = 7, 8, 26, 4
    # image a: 6 road (5 right, 1 sidewalk), 4 car (all right)
    ev.add("a", np.array([[road] * 6 + [car] * 4]), np.array([[road] * 5 + [sidewalk] + [car] * 4]), None, "a.png")
    # image b: 5 road (3 right, 2 car), 3 sidewalk (right), 2 static ground truth predicted road (void: no FP)
    ev.add("b", np.array([[road] * 5 + [sidewalk] * 3 + [static] * 2]),
           np.array([[road] * 3 + [car] * 2 + [sidewalk] * 3 + [road] * 2]), None, "b.png")
    res = ev.result()
    a, b = res["per_image"]
    assert a["iou"] == {"road": 5 / 6, "sidewalk": 0.0, "car": 1.0} and a["miou"] == pytest.approx((5 / 6 + 1) / 3)
    assert b["iou"] == {"road": 3 / 5, "sidewalk": 1.0, "car": 0.0}
    # pooled: road TP 8, FN 3, FP 0 (the static pixels are void); car TP 4, FP 2; sidewalk TP 3, FP 1
    assert res["classScores"]["road"] == 8 / 11 and res["classScores"]["car"] == 4 / 6
    assert res["classScores"]["sidewalk"] == 3 / 4 and res["classScores"]["static"] is None
    seed = {r["class"]: r for r in res["seed001"]["classes"]}
    # nothing ignored per image: in b, static (2 gt, 0 tp) has IoU 0 and road IoU 3/7
    assert seed["road"]["iou"] == pytest.approx((5 / 6 + 3 / 7) / 2) and seed["static"] == {
        "class": "static", "iou": 0.0, "images": 1}
    merged = {r["class"]: r["iou"] for r in res["seed001"]["merged_8"]}
    # flat: a all right (1.0); b 6 of 8 right, 2 cars, and 2 static pixels predicted road (nothing ignored)
    assert merged["flat"] == pytest.approx((1.0 + 6 / 10) / 2)


def test_bad_predictions_are_one_line_exit_2_and_nothing_is_written(perturbed, tmp_path, capsys):
    ds, export, _ = perturbed
    stem = "urbangen-day-clear_000004_000001"
    out = tmp_path / "res.json"

    def run(pred_array, name=f"{stem}_pred.png", **save):
        folder = tmp_path / f"p{run.n}"
        run.n += 1
        folder.mkdir()
        Image.fromarray(pred_array).save(folder / name, **save)
        code = cli.main(["eval", "--images", "--pred", str(folder), "--gt", str(export), "--json", str(out)])
        err = capsys.readouterr().err.strip().splitlines()
        return code, err
    run.n = 0

    good = np.full((60, 96), 7, np.uint8)
    code, err = run(np.full((50, 96), 7, np.uint8))
    assert code == 2 and len(err) == 1 and f"{stem}_pred.png: size:" in err[0]
    code, err = run(np.zeros((60, 96, 3), np.uint8))
    assert code == 2 and len(err) == 1 and "mode: is RGB" in err[0]
    bad_ids = good.copy()
    bad_ids[0, 0] = 77
    code, err = run(bad_ids)
    assert code == 2 and len(err) == 1 and "ids: values [77] are not classes of the label set cityscapes" in err[0]
    code, err = run(good, name="something_else.png")
    assert code == 2 and len(err) == 1 and "no prediction for any of the" in err[0]
    assert not out.exists()


def test_train_id_predictions_score_as_their_label_ids(perturbed, tmp_path, capsys):
    """A model writing train ids (255 = void) is read through --label-set cityscapes_trainids."""
    from generator.formats.cityscapes import train_ids

    ds, export, pred = perturbed
    trained = tmp_path / "trainids"
    trained.mkdir()
    for p in pred.rglob("*.png"):
        Image.fromarray(train_ids(np.array(Image.open(p)))).save(trained / p.name)
    ours = _ours(pred, export, tmp_path / "a.json")
    out = tmp_path / "b.json"
    # read as label ids, 255 is no Cityscapes class: refused, not scored as something else
    assert cli.main(["eval", "--images", "--pred", str(trained), "--gt", str(export), "--json", str(out)]) == 2
    assert "ids: values [255] are not classes of the label set cityscapes" in capsys.readouterr().err
    assert cli.main(["eval", "--images", "--pred", str(trained), "--gt", str(export), "--json", str(out),
                     "--label-set", "cityscapes_trainids"]) == 0
    via_set = json.loads(out.read_text())
    assert via_set["classScores"] == ours["classScores"] and via_set["categoryScores"] == ours["categoryScores"]
