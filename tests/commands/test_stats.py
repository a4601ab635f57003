"""``urbangen stats``: Table I and II of seed 003 on a tiny dataset written by the test itself."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from generator.cli import main
from generator.imaging.exr import LabelledImage, write_exr
from generator.imaging.metadata import class_pixels
from generator.labels import class_table

H, W = 12, 16
#: (frame, time, kind) of the tiny dataset: deliberately unbalanced.
IMAGES = [(0, "day", "clear"), (0, "night", "clear"), (0, "day", "fog"), (1, "day", "fog"),
          (1, "night", "rain_fog"), (2, "night", "wet"), (2, "night", "wet_fog")]


def make_dataset(root: Path) -> list[np.ndarray]:
    """Write EXR + metadata JSON per image; returns the class maps."""
    table = class_table()
    folder = root / "images"
    folder.mkdir(parents=True)
    maps = []
    for i, (frame, tod, kind) in enumerate(IMAGES):
        g = np.random.default_rng(i)
        cls = g.choice([1, 5, 8, 11, 12, 16, 19], size=(H, W), p=[.3, .1, .2, .05, .1, .05, .2]).astype(np.uint8)
        if i == 3:
            cls[:2] = table.id("person")  # a native-only class in one image
        name = f"{frame:06d}_{tod}_{kind}"
        write_exr(folder / f"{name}.exr", LabelledImage(np.zeros((H, W, 3), np.float32), cls,
                                                        np.zeros((H, W), np.uint32), np.ones((H, W), np.float32)))
        meta = {"image": name, "files": {"exr": f"{name}.exr"}, "frame": frame, "time_of_day": tod,
                "weather": {"kind": kind}, "classes_present": class_pixels(cls),
                "camera": {"intrinsics": {"width": W, "height": H}}}
        (folder / f"{name}.json").write_text(json.dumps(meta))
        maps.append(cls)
    return maps


def read_csv(path: Path) -> list[dict]:
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


@pytest.fixture
def dataset(tmp_path):
    root = tmp_path / "ds"
    return root, make_dataset(root)


def test_table1_equals_counts_computed_from_the_arrays(dataset, tmp_path):
    root, maps = dataset
    out = tmp_path / "out"
    assert main(["stats", str(root), "--out", str(out)]) == 0
    table = class_table()
    direct = np.bincount(np.concatenate([m.ravel() for m in maps]), minlength=len(table))
    rows = read_csv(out / "table1_pixels.csv")
    by_name = {r["class"]: r for r in rows}
    trees = by_name["Trees"]
    assert int(trees["total_pixels"]) == direct[table.id("tree_trunk")] + direct[table.id("tree_crown")]
    assert trees["native_classes"] == "tree_trunk + tree_crown"
    for r in rows:
        ids = [table.id(n) for n in r["native_classes"].split(" + ")]
        assert int(r["total_pixels"]) == int(direct[ids].sum()), r["class"]
        assert float(r["average_per_image"]) == pytest.approx(direct[ids].sum() / len(IMAGES), abs=0.01)
    assert by_name["person"]["seed003"] == "False" and by_name["Buildings"]["seed003"] == "True"
    assert sum(int(r["total_pixels"]) for r in rows) == len(IMAGES) * H * W
    totals = [int(r["total_pixels"]) for r in rows]
    assert totals == sorted(totals, reverse=True)
    names = {r["class"] for r in rows}
    assert names == set(table.seed003_names()) | {n for n, s in zip(table.names, table.to_seed003(), strict=False)
                                                  if s is None}


def test_table2_counts_images_per_weather_and_time(dataset, tmp_path):
    root, _ = dataset
    out = tmp_path / "out"
    assert main(["stats", str(root), "--out", str(out)]) == 0
    rows = read_csv(out / "table2_conditions.csv")
    assert [r["weather"] for r in rows] == ["clear", "fog", "rain", "rain_fog", "wet", "wet_fog", "total"]
    got = {(r["weather"], t): int(r[t]) for r in rows for t in ("day", "night", "total")}
    for kind in ("clear", "fog", "rain", "rain_fog", "wet", "wet_fog"):
        for t in ("day", "night"):
            assert got[kind, t] == sum(1 for _, tod, k in IMAGES if (k, tod) == (kind, t))
        assert got[kind, "total"] == got[kind, "day"] + got[kind, "night"]
    assert (got["total", "day"], got["total", "night"], got["total", "total"]) == (3, 4, 7)
    md = (out / "stats.md").read_text()
    assert "| Rain & fog | 0 | 1 | 1 |" in md and "| Total | 3 | 4 | 7 |" in md
    with Image.open(out / "pixels_per_class.png") as im:
        assert im.format == "PNG" and im.width > 400


def test_verify_passes_then_catches_a_wrong_count(dataset, tmp_path, capsys):
    root, _ = dataset
    assert main(["stats", str(root), "--verify", "--out", str(tmp_path / "ok")]) == 0
    bad = root / "images" / "000001_day_fog.json"
    meta = json.loads(bad.read_text())
    name = next(iter(meta["classes_present"]))
    meta["classes_present"][name] += 1
    bad.write_text(json.dumps(meta))
    out = tmp_path / "bad"
    capsys.readouterr()
    assert main(["stats", str(root), "--verify", "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert "000001_day_fog" in err and name in err and "000000_day_clear" not in err
    assert not out.exists()
    assert main(["stats", str(root), "--out", str(out)]) == 0  # the fast path trusts the metadata


def test_verify_reports_a_missing_exr(dataset, tmp_path, capsys):
    root, _ = dataset
    (root / "images" / "000002_night_wet.exr").unlink()
    assert main(["stats", str(root), "--verify", "--out", str(tmp_path / "o")]) == 1
    assert "000002_night_wet" in capsys.readouterr().err


@pytest.mark.parametrize("case", ["missing", "empty", "bad_json", "bad_kind", "unknown_class"])
def test_bad_input_is_one_line_exit_2_and_nothing_written(dataset, tmp_path, capsys, case):
    root, _ = dataset
    if case == "missing":
        root = tmp_path / "nope"
    elif case == "empty":
        root = tmp_path / "empty"
        (root / "images").mkdir(parents=True)
    elif case == "bad_json":
        (root / "images" / "000000_day_clear.json").write_text("{not json")
    elif case == "bad_kind":
        p = root / "images" / "000000_day_clear.json"
        p.write_text(p.read_text().replace('"clear"', '"snow"'))
    else:
        p = root / "images" / "000000_day_clear.json"
        p.write_text(p.read_text().replace('"road"', '"lava"'))
    out = tmp_path / "out"
    capsys.readouterr()
    assert main(["stats", str(root), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("urbangen stats:")
    if case in ("bad_json", "bad_kind", "unknown_class"):
        assert "000000_day_clear.json" in err
    assert not out.exists()


def test_report_is_deterministic_and_defaults_to_the_stats_folder(dataset):
    root, _ = dataset
    before = {p.name for p in root.iterdir()}
    assert main(["stats", str(root)]) == 0
    first = {p.name: p.read_bytes() for p in (root / "stats").iterdir() if p.is_file()}
    assert set(first) == {"stats.md", "table1_pixels.csv", "table2_conditions.csv", "pixels_per_class.png",
                          "cityscapes_classes.csv"}  # class mix: no scans in this dataset, so no LiDAR table
    assert {p.name for p in root.iterdir()} == before | {"stats"}  # nothing else in the dataset root
    assert main(["stats", str(root)]) == 0
    assert {p.name: p.read_bytes() for p in (root / "stats").iterdir() if p.is_file()} == first
