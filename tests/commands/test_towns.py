"""``render``, ``lidar`` and ``layout`` with a spec that sets ``town.redraw_every_frames``.

Such a spec shows a new town every N frames and none of them is drawn from the spec's own seed.
``render`` honours it as ``generate`` does (frame ``k`` shows town ``k // N``); ``layout`` and
``lidar`` build one town, so they take ``--town I`` and refuse the spec without it (one line,
exit 2, nothing written) rather than silently build a town no dataset of the spec contains.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from generator.cli import main
from generator.commands.render import towns_of
from generator.formats import semantickitti as sk
from generator.imaging.paths import image_path
from generator.jobs.towns import local_frame
from generator.layout import build_scene
from generator.spec import load_spec, parse_spec
from generator.spec.towns import town_spec
from generator.world.rig import Rig
from kits.cli_run import run_cli


def _spec(root, tmp_path, every: int | None = 2):
    doc = json.loads((root / "scenes" / "test_town.json").read_text())
    doc["town"]["redraw_every_frames"] = every
    path = tmp_path / ("towns.json" if every else "plain.json")
    path.write_text(json.dumps(doc))
    return path


@pytest.mark.parametrize("cmd", ["layout", "lidar"])
def test_one_town_commands_refuse_a_redrawing_spec_without_town(root, tmp_path, capsys, cmd):
    spec = _spec(root, tmp_path)
    out = tmp_path / "out"
    rc, err = run_cli(capsys, [cmd, str(spec), "--out", str(out)], tmp_path, out)
    assert rc == 2
    assert err.startswith(f"urbangen {cmd}: {spec}: town.redraw_every_frames = 2 draws a new town every 2 frames"), err
    assert "--town I" in err


@pytest.mark.parametrize("cmd", ["layout", "lidar"])
def test_town_option_on_a_spec_that_redraws_nothing_is_refused(root, tmp_path, capsys, cmd):
    spec = _spec(root, tmp_path, every=None)
    out = tmp_path / "out"
    rc, err = run_cli(capsys, [cmd, str(spec), "--out", str(out), "--town", "1"], tmp_path, out)
    assert rc == 2 and err.startswith(f"urbangen {cmd}: --town: {spec} re-draws no town"), err


@pytest.mark.parametrize("bad", ["-1", "x", "1.5"])
def test_bad_town_value_is_one_line(root, tmp_path, capsys, bad):
    spec = _spec(root, tmp_path)
    out = tmp_path / "out"
    rc, err = run_cli(capsys, ["layout", str(spec), "--out", str(out), f"--town={bad}"], tmp_path, out)
    assert rc == 2 and "--town" in err


def test_layout_builds_the_town_generate_draws(root, tmp_path, capsys):
    path = _spec(root, tmp_path)
    out = tmp_path / "out"
    assert main(["layout", str(path), "--out", str(out), "--town", "1", "--ppm", "1"]) == 0
    spec = load_spec(path)
    t1 = town_spec(spec, 1)
    summary = json.loads((out / "test_town_town1_summary.json").read_text())
    assert summary["digest"] == build_scene(t1).digest() != build_scene(town_spec(spec, 0)).digest()
    assert summary["seed"] == t1.seed != spec.seed
    assert summary["town"] == {"index": 1, "seed": t1.seed, "base_seed": spec.seed, "every_frames": 2}
    assert (out / "test_town_town1_map.png").stat().st_size > 0 and (out / "test_town_town1.glb").exists()


def test_lidar_casts_the_town_it_is_asked_for(root, tmp_path):
    path = _spec(root, tmp_path)
    spec = load_spec(path)
    scans = {}
    for town in (0, 1):
        out = tmp_path / f"out{town}"
        assert main(["lidar", str(path), "--out", str(out), "--frames", "1", "--town", str(town), "--no-bev"]) == 0
        meta = json.loads((out / "lidar" / "sequences" / "00" / "lidar_meta.json").read_text())
        t = town_spec(spec, town)
        assert meta["scene"]["town"] == {"index": town, "seed": t.seed, "base_seed": spec.seed, "every_frames": 2}
        assert meta["scene"]["scene_digest"] == build_scene(t).digest()
        scans[town] = sk.read_scan(out / "lidar" / "sequences" / "00" / "velodyne" / "000000.bin")
    assert not np.array_equal(scans[0][:1000], scans[1][:1000])  # two towns, two scans


def test_render_groups_frames_by_town_as_generate_does(root, tmp_path):
    spec = load_spec(_spec(root, tmp_path, every=3))
    towns = towns_of(spec, [7, 0, 2, 3, 4])
    assert [(t.town_index, first, frames) for t, first, frames in towns] == [
        (0, 0, [0, 2]),
        (1, 3, [3, 4]),
        (2, 6, [7]),
    ]
    assert [t.seed for t, _, _ in towns] == [town_spec(spec, i).seed for i in range(3)]
    plain = parse_spec(json.loads((root / "scenes" / "test_town.json").read_text()), "plain.json")
    assert towns_of(plain, [2, 1]) == [(plain, 0, [1, 2])]


@pytest.mark.blender
@pytest.mark.slow
def test_render_shows_town_k_over_n(root, tmp_path):
    """Frames 0-2 at a new town every 2 frames: frames 0, 1 of town 0, frame 2 of town 1 driven from its start."""
    path = _spec(root, tmp_path)
    spec = load_spec(path)
    out = tmp_path / "out"
    assert main(["-q", "render", str(path), "--config", "test", "--out", str(out), "--frames", "3",
                 "--variants", "day:clear"]) == 0
    for k, town in ((0, 0), (1, 0), (2, 1)):
        img = json.loads(image_path(out, f"{k:06d}_day_clear", ".json").read_text())
        assert img["town"]["index"] == town and img["seed"] == town_spec(spec, town).seed
    t1 = town_spec(spec, 1)
    start = local_frame(Rig.from_spec(t1, build_scene(t1)), 2, 2)  # town 1's drive starts at frame 2
    img = json.loads(image_path(out, "000002_day_clear", ".json").read_text())
    assert np.allclose(img["camera"]["position_m"], start.T_world_camera[:3, 3], atol=1e-3)
