"""``urbangen export coco``: pycocotools reads it and scores it against itself at AP 1; masks are the passes'."""

from __future__ import annotations

import contextlib
import io
import json

import numpy as np
import pytest
from PIL import Image

from generator import cli
from generator.formats import coco as C
from generator.imaging.exr import read_exr

pytest.importorskip("pycocotools")


@pytest.fixture(scope="module")
def coco(frozen_detection_dataset, tmp_path_factory):
    out = tmp_path_factory.mktemp("coco") / "coco"
    assert cli.main(["export", "coco", str(frozen_detection_dataset), str(out)]) == 0
    return out


def _ap(gt, kind: str) -> float:
    from pycocotools.cocoeval import COCOeval

    res = [{"image_id": a["image_id"], "category_id": a["category_id"], "bbox": a["bbox"],
            "segmentation": a["segmentation"], "score": 1.0} for a in gt.dataset["annotations"]]
    with contextlib.redirect_stdout(io.StringIO()):
        ev = COCOeval(gt, gt.loadRes(res), kind)
        ev.evaluate()
        ev.accumulate()
        ev.summarize()
    return float(ev.stats[0])


def test_every_image_is_there_and_scores_ap_1_against_itself(coco, frozen_detection_dataset):
    from pycocotools.coco import COCO

    with contextlib.redirect_stdout(io.StringIO()):
        gt = COCO(str(coco / "annotations" / "instances_val.json"))
    names = sorted(i["file_name"] for i in gt.dataset["images"])
    assert names == sorted(["000000_day_clear.png", "000001_day_clear.png"]
                           + [f"seq00_image_{c}_{j:06d}.png" for c in (2, 3) for j in (0, 10, 20)])
    assert all((coco / "images" / "val" / n).is_file() for n in names)
    assert len(gt.dataset["annotations"]) > 10
    assert _ap(gt, "bbox") == pytest.approx(1.0) and _ap(gt, "segm") == pytest.approx(1.0)


def test_masks_are_the_instance_pass_and_panoptic_segments_cover_the_image(coco, frozen_detection_dataset):
    from pycocotools import mask as M

    inst_doc = json.loads((coco / "annotations" / "instances_val.json").read_text())
    pan_doc = json.loads((coco / "annotations" / "panoptic_val.json").read_text())
    img = next(i for i in inst_doc["images"] if i["file_name"] == "seq00_image_2_000010.png")
    exr = read_exr(frozen_detection_dataset / "lidar" / "sequences" / "00" / "passes_2" / "000010.exr")
    anns = [a for a in inst_doc["annotations"] if a["image_id"] == img["id"]]
    assert anns
    for a in anns:
        m = M.decode({"size": a["segmentation"]["size"], "counts": a["segmentation"]["counts"].encode()}).astype(bool)
        assert np.array_equal(m, (exr.instance == a["instance_id"]) & (exr.class_id == a["category_id"]))
    pan = next(p for p in pan_doc["annotations"] if p["image_id"] == img["id"])
    ids = C.decode_panoptic(np.asarray(Image.open(coco / "annotations" / "panoptic_val" / pan["file_name"])))
    assert sorted(int(i) for i in np.unique(ids) if i) == sorted(s["id"] for s in pan["segments_info"])
    assert ((ids > 0) == (exr.class_id > 0)).all()
    cats = {c["id"]: c for c in pan_doc["categories"]}
    assert all(s["category_id"] in cats for s in pan["segments_info"])
    assert {cats[s["category_id"]]["isthing"] for s in pan["segments_info"]} == {0, 1}


def test_an_existing_export_is_refused_in_one_line(coco, frozen_detection_dataset, capsys):
    before = sorted(p.name for p in (coco / "annotations").iterdir())
    assert cli.main(["export", "coco", str(frozen_detection_dataset), str(coco)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "exists" in err[0]
    assert sorted(p.name for p in (coco / "annotations").iterdir()) == before
