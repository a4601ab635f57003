"""``fuse --image-labels``: a model's predictions projected onto the scans, written and scored (seed 001)."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest
from PIL import Image

from generator.cli import main
from generator.formats import semantickitti as sk
from generator.imaging.exr import read_exr
from generator.imaging.paths import find_image
from generator.labels import class_table
from generator.labels.class_sets import builtin_sets
from generator.stats.evaluate import iou_from_confusion
from kits.fusion_kit import write_raycast_images, write_raycast_stream

T = class_table()
HEAD = "occlusion=on,boundaries_and_proxies=excluded"
CAR, TRUCK = 26, 27


@pytest.fixture(scope="module")
def dataset(tmp_path_factory, test_spec, test_scene):
    """The test town: 2 ray-cast seed-003 frames, a 2-sweep sequence and a ray-cast image_2 of sweep 1."""
    from generator.jobs.lidar_sequence import SequenceOptions, write_sequence

    root = tmp_path_factory.mktemp("fuse_pred")
    write_raycast_images(root, test_scene, test_spec, 2, 640, 384)
    write_sequence(test_scene, test_spec, root / "lidar", SequenceOptions(frames=2, threads=2, bev=False),
                   progress=False)
    write_raycast_stream(root / "lidar" / "sequences" / "00", test_scene, test_spec, [1])
    return root


def _predictions(root, folder, swap=None):
    """The ground truth as a model's output: export-stem PNGs of the frames, image_2-named PNGs of the stream."""
    folder.mkdir(parents=True)
    maps = {f"urbangen-day-clear_000000_{k:06d}_pred.png": T.to_cityscapes[read_exr(
        find_image(root, f"{k:06d}_day_clear", ".exr")).class_id] for k in (0, 1)}
    maps["000001.png"] = np.array(Image.open(root / "lidar/sequences/00/semantic_2/000001.png"))
    for name, ids in maps.items():
        ids = ids.copy()
        if swap:
            ids[ids == swap[0]] = swap[1]
        Image.fromarray(ids.astype(np.uint8)).save(folder / name)
    return folder


def _run(root, pred, *extra) -> dict:
    assert main(["fuse", str(root), "--image-labels", str(pred), *extra]) == 0
    return json.loads((root / "fusion" / "predictions.json").read_text())


@pytest.fixture(scope="module")
def perfect(dataset, tmp_path_factory):
    return _run(dataset, _predictions(dataset, tmp_path_factory.mktemp("p") / "perfect"))


def test_a_perfect_prediction_scores_at_least_99_5_percent_on_fused_points(dataset, perfect):
    assert [v["kind"] for v in perfect["views"]] == ["frame", "frame", "image_2"]
    assert perfect["coverage"]["labelled_occlusion_on"] > 10_000
    for name in ("cityscapes", "seed001"):
        r = perfect["points"][name][HEAD]
        assert r["accuracy"] >= 0.995, name
        conf = np.array(r["confusion_pred_truth"])
        names = builtin_sets()[name].class_names()
        for c in range(len(conf)):
            if conf[:, c].sum() >= 100 and c not in builtin_sets()[name].ignore:
                assert r["iou"][names[c]] >= 0.995, (name, names[c], r["iou"][names[c]])
    assert perfect["map"]["accuracy"] >= 0.99
    # the tree: every scan, SemanticKITTI raw ids of the predicted classes, 0 where no image looked
    for k in (0, 1):
        pred, _ = sk.read_labels(dataset / "fusion/predicted/sequences/00/predictions" / f"{k:06d}.label")
        truth, _ = sk.read_labels(dataset / "lidar/sequences/00/labels" / f"{k:06d}.label")
        assert len(pred) == len(truth) and 0 < (pred > 0).mean() < 0.6
        both = (pred > 0) & np.isin(truth, (10, 40, 50))  # car, road, building: one raw id each way
        assert (pred[both] == truth[both]).mean() > 0.99
    for name in ("semantic_map_predicted.ply", "semantic_map_predicted_truth.ply",
                 "semantic_map_predicted_vs_truth.png", "predictions.md"):
        assert (dataset / "fusion" / name).stat().st_size > 100


def test_a_swapped_class_costs_exactly_the_analytic_loss(dataset, perfect, tmp_path):
    swapped = _run(dataset, _predictions(dataset, tmp_path / "swapped", swap=(CAR, TRUCK)))
    cs = builtin_sets()["cityscapes"]
    for variant in perfect["points"]["cityscapes"]:
        c = np.array(perfect["points"]["cityscapes"][variant]["confusion_pred_truth"])
        assert c[CAR, CAR] > 100  # there are cars to swap
        c[TRUCK] += c[CAR]  # every point predicted car is now predicted truck
        c[CAR] = 0
        want = iou_from_confusion(c, ignore=cs.ignore, mean_over="all")
        got = swapped["points"]["cityscapes"][variant]
        assert got["iou"]["car"] == 0.0 and got["miou"] == want.miou
        assert got["iou"]["truck"] == want.iou[TRUCK]
    # seed 001 merges car and truck into vehicle: the swap costs nothing there
    assert swapped["points"]["seed001"] == perfect["points"]["seed001"]


def test_without_deskew_the_stream_is_projected_the_kitti_way(dataset, perfect, tmp_path):
    """--no-deskew: raw points, P2 @ Tr for image_2 (what KITTI tools do); still mostly right, a little worse."""
    raw = _run(dataset, _predictions(dataset, tmp_path / "raw"), "--no-deskew")
    assert raw["settings"]["deskew"].startswith("off")
    r, p = raw["points"]["cityscapes"][HEAD], perfect["points"]["cityscapes"][HEAD]
    assert 0.9 < r["accuracy"] <= p["accuracy"]


def _bad(dataset, tmp_path, capsys, name, array=None, extra=()):
    pred = tmp_path / "bad"
    shutil.copytree(_predictions(dataset, tmp_path / "good"), pred)
    if array is not None:
        Image.fromarray(array).save(pred / name)
    before = sorted(p.relative_to(dataset) for p in dataset.rglob("*"))
    code = main(["fuse", str(dataset), "--image-labels", str(pred), *extra])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1, err
    assert sorted(p.relative_to(dataset) for p in dataset.rglob("*")) == before  # nothing written
    return err[0]


def test_a_png_of_the_wrong_size_is_refused(dataset, tmp_path, capsys):
    err = _bad(dataset, tmp_path, capsys, "000001.png", np.zeros((10, 10), np.uint8))
    assert "000001.png: size: 10 x 10 pixels, but the image it labels is 640 x 360" in err


def test_a_colour_png_is_refused(dataset, tmp_path, capsys):
    err = _bad(dataset, tmp_path, capsys, "000001.png", np.zeros((360, 640, 3), np.uint8))
    assert "000001.png: mode: is RGB" in err


def test_unknown_label_ids_are_refused(dataset, tmp_path, capsys):
    ids = np.full((384, 640), 7, np.uint8)
    ids[5, 5] = 250
    err = _bad(dataset, tmp_path, capsys, "urbangen-day-clear_000000_000001_pred.png", ids)
    assert "_000001_pred.png: ids: values [250] are not classes of the label set cityscapes" in err


def test_a_label_set_that_maps_to_nothing_is_refused(dataset, tmp_path, capsys):
    f = tmp_path / "nothing.yaml"
    f.write_text("base: cityscapes\nignore: [0]\nclasses: {0: {name: void, members: [road]}, 1: {name: car}}\n")
    err = _bad(dataset, tmp_path, capsys, "", extra=("--label-set", str(f)))
    assert f"{f}: classes: maps to nothing" in err
