"""``urbangen flow DIR``: the motion ground truth of an existing dataset.

Bad input is one line, exit 2, nothing written."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from generator import cli
from generator.dataset import Dataset
from generator.imaging.paths import find_image
from kits import motion_kit as mk


@pytest.fixture(autouse=True)
def cached_scene(monkeypatch, test_scene):
    """The command rebuilds the town from the manifest's spec: the session's test town stands in."""
    import generator.layout

    monkeypatch.setattr(generator.layout, "build_scene", lambda spec: test_scene)


def _files(root: Path) -> set[str]:
    return {str(p.relative_to(root)) for p in root.rglob("*")}


def _run(capsys, root):
    capsys.readouterr()
    rc = cli.main(["flow", str(root)])
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    return rc, out, err


def test_flow_of_an_existing_dataset(tmp_path, capsys, test_spec, test_scene):
    mk.write_dataset(tmp_path, test_spec, test_scene, 3, stereo_sweeps=(0, 10))
    rc, out, _ = _run(capsys, tmp_path)
    assert rc == 0, out
    ds = Dataset(tmp_path)
    assert ds.image_flow("000000_day_clear").forward is not None
    assert ds.stereo_flow(0, 2).forward is not None and ds.disparity(10) is not None
    assert (tmp_path / "flow/flow_noc/000001.png").is_file() and not (tmp_path / "flow/flow_noc/000002.png").exists()
    assert "images: 3 images" in out and not list(tmp_path.rglob(".tmp*"))


@pytest.mark.parametrize("channel", ["depth.Z", "instance.id"])
def test_a_dataset_without_a_pass_is_refused(tmp_path, capsys, test_spec, test_scene, channel):
    mk.write_dataset(tmp_path, test_spec, test_scene, 2, drop_channel=channel)
    before = _files(tmp_path)
    rc, _, err = _run(capsys, tmp_path)
    assert rc == 2 and err.count("\n") == 1 and channel in err and "000000_day_clear.exr" in err
    assert _files(tmp_path) == before


def test_a_stream_of_one_image_is_refused(tmp_path, capsys, test_spec, test_scene):
    mk.write_dataset(tmp_path, test_spec, test_scene, 1)
    before = _files(tmp_path)
    rc, _, err = _run(capsys, tmp_path)
    assert rc == 2 and err.count("\n") == 1 and "a stream of one image" in err
    assert _files(tmp_path) == before


def test_a_stereo_stream_of_one_pair_is_refused(tmp_path, capsys, test_spec, test_scene):
    mk.write_dataset(tmp_path, test_spec, test_scene, 2, stereo_sweeps=(0,))
    before = _files(tmp_path)
    rc, _, err = _run(capsys, tmp_path)
    assert rc == 2 and "image_2" in err and "a stream of one image" in err
    assert _files(tmp_path) == before


def test_a_folder_without_a_manifest_is_refused(tmp_path, capsys, test_spec, test_scene):
    mk.write_dataset(tmp_path, test_spec, test_scene, 2)
    (tmp_path / "manifest.json").unlink()
    rc, _, err = _run(capsys, tmp_path)
    assert rc == 2 and "manifest.json: missing" in err


def test_a_damaged_image_json_is_refused(tmp_path, capsys, test_spec, test_scene):
    mk.write_dataset(tmp_path, test_spec, test_scene, 2)
    meta = find_image(tmp_path, "000001_day_clear", ".json")
    doc = json.loads(meta.read_text())
    doc["camera"]["T_world_camera"] = [[1, 0], [0, 1]]
    meta.write_text(json.dumps(doc))
    before = _files(tmp_path)
    rc, _, err = _run(capsys, tmp_path)
    assert rc == 2 and "T_world_camera" in err and err.count("\n") == 1
    assert _files(tmp_path) == before
