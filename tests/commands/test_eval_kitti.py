"""``urbangen eval --detection kitti``: AP on label folders; bad input is one line, exit 2, nothing written."""

from __future__ import annotations

import json

import pytest

from generator import cli
from kits.kitti_kit import as_predictions, synthetic, write_dir


@pytest.fixture
def folders(tmp_path):
    gts, dts = synthetic(seed=26, frames=6)
    write_dir(tmp_path / "gt", gts)
    write_dir(tmp_path / "pred", [as_predictions(g) for g in gts])
    return tmp_path


def _run(capsys, *argv):
    capsys.readouterr()
    rc = cli.main(["eval", "--detection", "kitti", *map(str, argv)])
    return rc, capsys.readouterr()


def test_scores_and_writes_json(folders, capsys):
    rc, out = _run(capsys, "--gt", folders / "gt", "--pred", folders / "pred")
    assert rc == 0 and "Car AP_R40@0.70" in out.out
    doc = json.loads((folders / "pred" / "eval_kitti.json").read_text())
    assert doc["samples"] == 6 and set(doc["classes"]) == {"Car", "Pedestrian", "Cyclist"}


@pytest.mark.parametrize("where, damage, field", [
    ("pred", lambda line: line.replace(line.split()[11], "nan", 1), "line 1: x"),      # a NaN
    ("pred", lambda line: "Airplane" + line[line.index(" "):], "line 1: type"),        # an unknown class
    ("gt", lambda line: " ".join(line.split()[:9]), "line 1"),                          # a truncated label line
    ("pred", lambda line: " ".join(line.split()[:15]), "line 1"),                       # a prediction without score
])
def test_bad_input_is_one_line_naming_file_and_field(folders, capsys, where, damage, field):
    path = folders / where / "000002.txt"
    lines = path.read_text().splitlines()
    path.write_text("\n".join([damage(lines[0]), *lines[1:]]) + "\n")
    rc, out = _run(capsys, "--gt", folders / "gt", "--pred", folders / "pred")
    err = out.err.strip()
    assert rc == 2 and "\n" not in err and "Traceback" not in err
    assert "000002.txt" in err and field in err
    assert not (folders / "pred" / "eval_kitti.json").exists()


def test_a_missing_prediction_file_is_named(folders, capsys):
    (folders / "pred" / "000003.txt").unlink()
    rc, out = _run(capsys, "--gt", folders / "gt", "--pred", folders / "pred")
    assert rc == 2 and "000003.txt" in out.err and not (folders / "pred" / "eval_kitti.json").exists()


def test_unknown_class_option(folders, capsys):
    rc, out = _run(capsys, "--gt", folders / "gt", "--pred", folders / "pred", "--classes", "Tram")
    assert rc == 2 and "--classes" in out.err
