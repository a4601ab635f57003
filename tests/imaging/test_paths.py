"""The one path helper of a dataset's images (:mod:`generator.imaging.paths`): shards of bounded size,
old flat datasets still read, and no other module spells the images folder itself."""

from __future__ import annotations

import ast
from pathlib import Path

from generator.imaging import paths as P
from kits.paths import ROOT


def _touch(path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(b"")
    return path


def test_a_frame_and_its_variants_share_a_shard_of_a_hundred_frames(tmp_path):
    assert P.image_path(tmp_path, "001234_day_clear") == tmp_path / "images" / "0012" / "001234_day_clear.exr"
    assert P.image_path(tmp_path, "001234_night_rain_fog", "_preview.png").parent.name == "0012"
    assert P.image_relpath("999999_dusk_wet", ".json") == "images/9999/999999_dusk_wet.json"
    shards = {P.shard_name(k) for k in range(0, 1_000_000, 7)}
    assert len(shards) == 10_000 and max(shards) == "9999"  # every six-digit frame: 10 000 folders
    per_shard = {P.shard_name(k) for k in range(1200, 1300)}
    assert per_shard == {"0012"} and P.shard_name(1300) == "0013"  # 100 frames a folder


def test_readers_find_sharded_and_flat_images_in_name_order(tmp_path):
    sharded = [_touch(P.image_path(tmp_path, f"{k:06d}_day_clear", ".json")) for k in (0, 99, 100, 4321)]
    flat = _touch(tmp_path / "images" / "000050_day_fog.json")  # a dataset written before the shards
    _touch(tmp_path / "images" / "0043" / "not_an_image.txt")
    assert P.find_image(tmp_path, "000050_day_fog", ".json") == flat
    assert P.find_image(tmp_path, "000099_day_clear", ".json") == sharded[1]
    assert P.find_image(tmp_path, "000007_day_clear", ".json") == P.image_path(tmp_path, "000007_day_clear", ".json")
    assert P.image_files(tmp_path, "*.json") == [sharded[0], flat, *sharded[1:]]
    assert P.image_files(tmp_path, "*.json", frames=[100, 50]) == [flat, sharded[2]]
    assert P.image_files(tmp_path, "*.json", frames=[7]) == []
    assert P.has_images(tmp_path, "*.json") and not P.has_images(tmp_path, "*.exr")
    assert P.image_files(tmp_path / "nowhere") == [] and not P.has_images(tmp_path / "nowhere")
    assert [d.name for d in P.shard_dirs(tmp_path)] == ["0000", "0001", "0043"]


def _name(func) -> str:
    return func.attr if isinstance(func, ast.Attribute) else func.id if isinstance(func, ast.Name) else ""


def test_only_the_helper_spells_the_images_folder():
    """Every reader and writer goes through generator.imaging.paths: nobody else joins "images" onto a path."""
    bad = []
    for path in sorted(ROOT.glob("generator/**/*.py")):
        if path.name == "paths.py" and path.parent.name == "imaging":
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            joined = isinstance(node, ast.BinOp) and isinstance(node.op, ast.Div) and \
                isinstance(node.right, ast.Constant) and node.right.value == "images"
            called = isinstance(node, ast.Call) and _name(node.func) in ("inside", "joinpath", "Path", "join") and \
                any(isinstance(a, ast.Constant) and a.value == "images" for a in node.args)
            if joined or called:
                bad.append(f"{path.relative_to(ROOT)}:{node.lineno}")
    assert not bad, "use generator.imaging.paths instead: " + ", ".join(bad)
