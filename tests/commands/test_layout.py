"""``urbangen layout``: the happy path writes a readable map, GLB and summary; every kind of
bad input is one line on stderr, exit code 2, and nothing written."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import trimesh
from PIL import Image

from generator.cli import main
from generator.labels import class_table
from generator.layout.network.draw import make_grid
from generator.spec import load_spec
from kits.paths import ROOT


def test_layout_writes_map_glb_and_summary(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["-q", "layout", str(ROOT / "scenes" / "test_town.json"), "--out", str(out)]) == 0
    assert sorted(p.name for p in out.iterdir()) == ["test_town.glb", "test_town_map.png", "test_town_summary.json"]
    assert capsys.readouterr().out.split() == [str(out / n) for n in ("test_town_map.png", "test_town.glb",
                                                                      "test_town_summary.json")]

    summary = json.loads((out / "test_town_summary.json").read_text())
    classes = summary["classes"]
    assert set(classes) == set(class_table().names)
    assert sum(c["triangles"] for c in classes.values()) == summary["totals"]["triangles"]
    assert sum(c["objects"] for c in classes.values()) == summary["totals"]["objects"]
    assert classes["building"]["objects"] > 0 and classes["car"]["objects"] > 0
    assert summary["seed"] == 7 and len(summary["spec_hash"]) == 64
    assert summary["routes"][0]["closed"] and summary["routes"][0]["length_m"] > 100

    with Image.open(out / "test_town_map.png") as img:
        img.load()
        rgb = np.asarray(img.convert("RGB"))
    assert min(rgb.shape[:2]) > 500
    # the map frames the built town and its margin, not the ground that runs on to the horizon
    grid = make_grid(load_spec(ROOT / "scenes" / "test_town.json"))
    assert np.allclose(summary["bounds_m"], grid.bounds, atol=1e-3)
    bx0, by0, bx1, by1 = grid.built_rect
    assert np.allclose(grid.bounds, [[bx0 - 12, by0 - 12], [bx1 + 12, by1 + 12]])
    assert rgb.shape[0] == max(560, int(np.ceil((grid.bounds[1, 1] - grid.bounds[0, 1]) * 8.0)))
    table = class_table()
    seen = {tuple(c) for c in np.unique(rgb.reshape(-1, 3), axis=0).tolist()}
    # flat, level surfaces are drawn in exactly their class colour (only slopes are shaded)
    for name in ("road", "road_marking", "crosswalk", "sidewalk", "parking", "terrain", "building"):
        assert tuple(table.colors[table.id(name)].tolist()) in seen, name

    glb = trimesh.load(out / "test_town.glb")
    assert set(glb.geometry) == {n for n, c in classes.items() if c["triangles"]}
    assert sum(len(g.faces) for g in glb.geometry.values()) == summary["totals"]["triangles"]
    assert glb.bounds[0][1] == pytest.approx(0.0, abs=0.01), "glTF is y-up: the ground is at y = 0"


def _write(tmp_path: Path, name: str, text: str) -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


BAD = {
    "malformed_json": ('{"name": "x", "seed": 1,',
                       "invalid JSON at line 1 column 25: Expecting property name enclosed in double quotes"),
    "unknown_key": ('{"name": "x", "seed": 1, "town": {"blocks": 3}}',
                    "town.blocks: unknown key (allowed here: block_size_jitter_m, block_size_m, blocks_x, blocks_y, "
                    "curb_height_m, lane_width_m, lanes_per_direction, margin_m, parking_strip_width_m, "
                    "redraw_every_frames, sidewalk_width_m)"),
    "wrong_type": ('{"name": "x", "seed": 1, "density": {"trees_per_100m": "many"}}',
                   'density.trees_per_100m: must be a number in [0, 30], got "many"'),
    "out_of_range": ('{"name": "x", "seed": 1, "town": {"lanes_per_direction": 7}}',
                     "town.lanes_per_direction: must be an integer in [1, 3], got 7"),
}


@pytest.mark.parametrize("kind", sorted(BAD))
def test_bad_spec_is_one_line_exit_2_nothing_written(kind, tmp_path, capsys):
    text, reason = BAD[kind]
    spec = _write(tmp_path, f"{kind}.json", text)
    out = tmp_path / "out"
    assert main(["layout", str(spec), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err == f"urbangen layout: {spec}: {reason}\n"
    assert not out.exists()


def test_missing_spec_file(tmp_path, capsys):
    out = tmp_path / "out"
    missing = tmp_path / "nothere.json"
    assert main(["layout", str(missing), "--out", str(out)]) == 2
    assert capsys.readouterr().err == f"urbangen layout: {missing}: file not found\n"
    assert not out.exists()


def test_out_must_be_a_folder(tmp_path, capsys):
    out = _write(tmp_path, "taken", "")
    assert main(["layout", str(ROOT / "scenes" / "test_town.json"), "--out", str(out)]) == 2
    assert capsys.readouterr().err == f"urbangen layout: --out: {out}: exists and is a file, not a folder\n"
    assert out.read_text() == ""


def test_console_script_reports_bad_spec(tmp_path):
    """The installed entry point behaves like ``main`` (one line on stderr, exit 2)."""
    spec = _write(tmp_path, "bad.json", BAD["out_of_range"][0])
    out = tmp_path / "out"
    r = subprocess.run([sys.executable, "-m", "generator.cli", "layout", str(spec), "--out", str(out)],
                       capture_output=True, text=True, cwd=tmp_path)
    assert r.returncode == 2
    assert r.stderr.splitlines() == [f"urbangen layout: {spec}: {BAD['out_of_range'][1]}"]
    assert not out.exists()
