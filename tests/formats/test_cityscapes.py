"""``urbangen export cityscapes``: the Cityscapes layout, ids cityscapesScripts reads, and its own score.

Fixtures are written with :func:`generator.imaging.exr.write_exr` (no Blender): a class map
with stuff, things with native instance ids and a thing pixel without one.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest
from PIL import Image

import generator.cli as cli
from generator.formats import cityscapes as cs
from generator.imaging.exr import LabelledImage, write_exr
from generator.labels import class_table
from generator.previews.preview import tonemap

T = class_table()
VARIANTS = (("day", "clear"), ("night", "rain_fog"), ("day", "wet_fog"))


@pytest.fixture(autouse=True)
def only_export(monkeypatch):
    monkeypatch.setattr(cli, "COMMANDS", ["export"])


def _image(frame: int) -> LabelledImage:
    """Sky over buildings over road with markings; two cars, a person and an instance-less truck pixel block."""
    h, w = 48, 64
    cls = np.full((h, w), T.id("road"), np.uint8)
    cls[:12] = T.id("sky")
    cls[12:24] = T.id("building")
    cls[24:28, :] = T.id("sidewalk")
    cls[40:42, ::4] = T.id("road_marking")
    cls[30:36, 20:24] = T.id("pole")
    inst = np.zeros((h, w), np.uint32)
    for (r, c, name, i) in ((28, 2, "car", 905 + frame), (28, 30, "car", 77), (26, 50, "person", 3),
                            (34, 40, "truck", 0)):
        cls[r:r + 6, c:c + 8] = T.id(name)
        inst[r:r + 6, c:c + 8] = i
    rgb = np.random.default_rng(frame).uniform(0, 3, (h, w, 3)).astype(np.float32)
    depth = np.where(cls == T.id("sky"), np.inf, 10.0).astype(np.float32)
    return LabelledImage(rgb, cls, inst, depth)


@pytest.fixture
def dataset(tmp_path):
    root = tmp_path / "ds"
    for frame in (0, 1):
        im = _image(frame)
        for time_of_day, weather in VARIANTS:
            name = f"{frame:06d}_{time_of_day}_{weather}"
            write_exr(root / "images" / f"{name}.exr", im)
            meta = {"image": name, "frame": frame, "time_of_day": time_of_day, "weather": {"kind": weather}}
            (root / "images" / f"{name}.json").write_text(json.dumps(meta))
    (root / "manifest.json").write_text(json.dumps({"plan": {"sequence": "03", "frames": [0, 1]}}))
    return root


def _png(path) -> np.ndarray:
    return np.array(Image.open(path))


def test_export_writes_the_cityscapes_layout_with_unique_stems(dataset, tmp_path, capsys):
    out = tmp_path / "cs"
    assert cli.main(["export", "cityscapes", str(dataset), str(out)]) == 0
    assert "exported 6 images" in capsys.readouterr().out
    labels = sorted(out.glob("gtFine/val/*/*_gtFine_labelIds.png"))
    stems = [p.name[: -len("_gtFine_labelIds.png")] for p in labels]
    assert len(stems) == len(set(stems)) == 6  # 2 frames x 3 variants, one name each
    assert "urbangen-night-rain-fog_000003_000001" in stems
    assert all(len(s.split("_")) == 3 for s in stems)  # city, sequence, frame: what cityscapesScripts parses
    im = _image(1)
    base = out / "gtFine" / "val" / "urbangen-day-wet-fog" / "urbangen-day-wet-fog_000003_000001"
    lab = _png(f"{base}_gtFine_labelIds.png")
    assert lab.dtype == np.uint8 and np.array_equal(lab, T.to_cityscapes[im.class_id])
    assert set(np.unique(lab)) == {7, 8, 11, 17, 23, 24, 26, 27}  # road markings are road
    inst = _png(f"{base}_gtFine_instanceIds.png")
    assert inst.dtype == np.uint16
    # cars numbered 0, 1 in the order of their native ids (77 < 906); the person 24000; the truck
    # without a native instance keeps its plain label id; stuff keeps its label id
    assert inst[29, 31] == 26000 and inst[29, 3] == 26001 and inst[27, 51] == 24000 and inst[35, 41] == 27
    stuff = ~np.isin(lab, cs.INSTANCE_LABEL_IDS)
    assert np.array_equal(inst[stuff], lab[stuff]) and np.array_equal(np.where(inst >= 1000, inst // 1000, inst), lab)
    assert np.array_equal(_png(f"{base}_gtFine_labelTrainIds.png"), cs.train_ids(lab))
    color = _png(f"{base}_gtFine_color.png")
    assert color.shape == (48, 64, 4) and tuple(color[0, 0]) == (70, 130, 180, 255)
    left = out / "leftImg8bit" / "val" / "urbangen-day-wet-fog" / "urbangen-day-wet-fog_000003_000001_leftImg8bit.png"
    rgb = _png(left)
    assert rgb.shape == (48, 64, 3) and rgb.dtype == np.uint8
    np.testing.assert_allclose(rgb, tonemap(im.rgb), atol=1)  # the preview's tone mapping (EXR RGB is half)
    assert not list(out.glob(".tmp-*"))


def test_label_table_is_cityscapesscripts_own():
    labels = pytest.importorskip("cityscapesscripts.helpers.labels")
    theirs = {lb.id: (lb.name, lb.trainId, lb.hasInstances, tuple(lb.color)) for lb in labels.labels if lb.id >= 0}
    assert theirs == cs.LABELS
    for row in T.rows:  # every class of the table maps to a Cityscapes id
        assert row.cityscapes in cs.LABELS, row.name


def test_cityscapesscripts_scores_the_export_against_itself_100_percent(dataset, tmp_path):
    pytest.importorskip("cityscapesscripts")
    out, results, report = tmp_path / "cs", tmp_path / "results", tmp_path / "report"
    assert cli.main(["export", "cityscapes", str(dataset), str(out)]) == 0
    results.mkdir()
    report.mkdir()
    for p in out.glob("gtFine/val/*/*_gtFine_labelIds.png"):  # a perfect "prediction": the labels themselves
        shutil.copy(p, results / p.name.replace("_gtFine_labelIds", "_pred"))
    env = {**os.environ, "CITYSCAPES_DATASET": str(out), "CITYSCAPES_RESULTS": str(results),
           "CITYSCAPES_EXPORT_DIR": str(report)}
    run = subprocess.run([sys.executable, "-m", "cityscapesscripts.evaluation.evalPixelLevelSemanticLabeling"],
                         env=env, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-2000:]
    res = json.loads((report / "resultPixelLevelSemanticLabeling.json").read_text())
    assert res["averageScoreClasses"] == pytest.approx(1.0) and res["averageScoreInstClasses"] == pytest.approx(1.0)
    scored = {k for k, v in res["classScores"].items() if v == v}  # NaN: class in neither image set
    assert {"road", "sidewalk", "building", "pole", "sky", "person", "car", "truck"} == scored


def test_bad_input_is_one_line_exit_2_and_nothing_is_written(dataset, tmp_path, capsys):
    out = tmp_path / "cs"
    assert cli.main(["export", "cityscapes", str(tmp_path / "nope"), str(out)]) == 2
    assert cli.main(["export", "cityscapes", str(tmp_path), str(out)]) == 2  # no images/
    (dataset / "images" / "000001_day_clear.json").unlink()
    assert cli.main(["export", "cityscapes", str(dataset), str(out)]) == 2
    assert "000001_day_clear.json: missing" in capsys.readouterr().err and not out.exists()
    # a file already in place is never overwritten, and the export stops before writing anything
    (dataset / "images" / "000001_day_clear.json").write_text(json.dumps(
        {"frame": 1, "time_of_day": "day", "weather": {"kind": "clear"}}))
    target = out / "gtFine" / "train" / "urbangen-day-clear" / "urbangen-day-clear_000003_000001_gtFine_color.png"
    target.parent.mkdir(parents=True)
    target.write_bytes(b"mine")
    assert cli.main(["export", "cityscapes", str(dataset), str(out), "--split", "train"]) == 2
    assert "exists" in capsys.readouterr().err and target.read_bytes() == b"mine"
    assert [p for p in out.rglob("*") if p.is_file()] == [target]
    # a broken EXR found mid-way leaves nothing behind either
    (dataset / "images" / "000001_night_rain_fog.exr").write_bytes(b"not an exr")
    assert cli.main(["export", "cityscapes", str(dataset), str(tmp_path / "cs2")]) == 2
    assert not (tmp_path / "cs2").exists()
