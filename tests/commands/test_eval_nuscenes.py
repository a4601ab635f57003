"""``urbangen eval --detection nuscenes``: the result file and table; bad predictions are one line, exit 2,
nothing written."""

from __future__ import annotations

import copy
import json
import sys

import pytest

from generator import cli
from generator.stats import detection_nuscenes as dn

pytest.importorskip("nuscenes")


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    from kits.detection_data import tiny_nuscenes

    root = tiny_nuscenes(tmp_path_factory.mktemp("tiny_cli") / "nus")
    return root, dn.ground_truth_predictions(root)


def _run(tmp_path, root, preds, capsys, *extra):
    pred = tmp_path / "pred.json"
    pred.write_text(preds if isinstance(preds, str) else json.dumps(preds))
    out = tmp_path / "result.json"
    code = cli.main(["eval", "--detection", "nuscenes", "--pred", str(pred), "--gt", str(root), "--json", str(out),
                     *extra])
    return code, capsys.readouterr(), out


def test_the_command_writes_the_devkits_metrics(tiny, tmp_path, capsys):
    root, gt = tiny
    code, io, out = _run(tmp_path, root, gt, capsys)
    assert code == 0
    r = json.loads(out.read_text())
    assert r["mAP"] == pytest.approx(1.0) and r["NDS"] == pytest.approx(1.0) and r["split"] == "urbangen_val"
    assert "mAP 1.000  NDS 1.000" in io.out and "AP@0.5" in io.out


def _nan(gt):
    p = copy.deepcopy(gt)
    tok = next(iter(p["results"]))
    p["results"][tok][0]["translation"][1] = float("nan")
    return json.dumps(p), f"results.{tok}[0].translation[1]"


def _unknown_class(gt):
    p = copy.deepcopy(gt)
    tok = next(iter(p["results"]))
    p["results"][tok][1]["detection_name"] = "hovercraft"
    return json.dumps(p), f"results.{tok}[1].detection_name"


def _wrong_token(gt):
    p = copy.deepcopy(gt)
    p["results"]["0123456789abcdef0123456789abcdef"] = []
    return json.dumps(p), "results.0123456789abcdef0123456789abcdef"


def _missing_sample(gt):
    p = copy.deepcopy(gt)
    tok = next(iter(p["results"]))
    del p["results"][tok]
    return json.dumps(p), f"results.{tok}"


def _negative_size(gt):
    p = copy.deepcopy(gt)
    tok = next(iter(p["results"]))
    p["results"][tok][0]["size"][0] = -1.0
    return json.dumps(p), f"results.{tok}[0].size[0]"


@pytest.mark.parametrize("make", [_nan, _unknown_class, _wrong_token, _missing_sample, _negative_size])
def test_bad_predictions_are_one_line_naming_file_and_field_exit_2_nothing_written(tiny, tmp_path, capsys, make):
    root, gt = tiny
    text, field = make(gt)
    code, io, out = _run(tmp_path, root, text, capsys)
    lines = io.err.strip().splitlines()
    assert code == 2 and len(lines) == 1, io.err
    assert "pred.json" in lines[0] and field in lines[0]
    assert not out.exists()


def test_a_split_that_does_not_exist_and_a_folder_that_is_no_export(tiny, tmp_path, capsys):
    root, gt = tiny
    code, io, out = _run(tmp_path, root, gt, capsys, "--split", "mini_val")
    assert code == 2 and "--split" in io.err and "urbangen_val" in io.err and not out.exists()
    code, io, out = _run(tmp_path, tmp_path, gt, capsys)
    assert code == 2 and "v1.0-*" in io.err and not out.exists()


def test_without_the_devkit_one_line_says_how_to_install_it(tiny, tmp_path, capsys, monkeypatch):
    root, gt = tiny
    monkeypatch.setitem(sys.modules, "nuscenes", None)
    code, io, out = _run(tmp_path, root, gt, capsys)
    assert code == 2 and io.err.strip() == f"urbangen eval: {dn.INSTALL_HINT}" and not out.exists()
