"""Plan-size limits and the disk estimate, checked before any work (issue 16).

An absurd ``--frames`` used to run until killed or die with MemoryError; a run bigger than
the free disk died half-way. Now :mod:`generator.jobs.plan` refuses both in one line before
the first write, and its estimates are checked here against what a real run writes.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
from collections import namedtuple
from pathlib import Path
from unittest import mock

import pytest

from generator import cli
from generator.errors import UserError
from generator.jobs import plan as P
from kits.paths import ROOT

SPEC = str(ROOT / "scenes" / "test_town.json")
Usage = namedtuple("Usage", "total used free")


def test_check_plan_limits_are_the_file_names():
    """No cap on images: a million images (and more) are planned; frame numbers stop at six digits."""
    P.check_plan(P.make_plan(2))
    million = P.make_plan(83_334)  # 83 334 frames x 12 variants = 1 000 008 images
    P.check_plan(million)
    assert million.n_images == 1_000_008 and million.to_dict()["frame_ranges"] == [[0, 83_334]]
    P.check_plan(P.make_plan(P.MAX_FRAMES, combos=[("day", "clear")]))  # every six-digit frame number
    with pytest.raises(UserError, match=r"frame 1000000 planned; frame numbers must stay in 0\.\.999999"):
        P.check_plan(P.make_plan(2, first=999_999, combos=[("day", "clear")]))
    P.check_plan(P.make_plan(1, first=999_999, combos=[("day", "clear")]))


def test_check_workers(monkeypatch):
    monkeypatch.setattr(os, "cpu_count", lambda: 4)
    P.check_workers(4, "local")
    P.check_workers(200, "ray")  # a cluster: not bounded by this machine's cores
    with pytest.raises(UserError, match="--workers: 5 local workers but this machine has 4 cores"):
        P.check_workers(5, "local")
    monkeypatch.setattr(os, "cpu_count", lambda: 1)
    P.check_workers(2, "local")  # two workers are always allowed (one sets up while the other renders)


def test_image_estimate_is_near_what_the_presets_write():
    # measured: preview preset (640x360, zip, 35 classes): EXR 1.6-1.7 MB, preview PNG 0.28 MB, JSON 4 KB
    est = P.image_bytes(640, 360, "zip", 35, True)
    assert 1.9e6 <= est <= 2.6e6
    assert P.image_bytes(640, 360, "none", 35, True) > 3 * P.image_bytes(640, 360, "zip", 35, False)


def test_scan_estimate_bounds_what_a_scan_writes(tmp_path, test_spec, test_scene):
    from generator.jobs.lidar_sequence import SequenceOptions, write_sequence
    from generator.lidar.sensors import sensor_for_spec

    write_sequence(test_scene, test_spec, tmp_path, SequenceOptions(frames=1, threads=2), progress=False)
    seq = tmp_path / "sequences" / "00"
    per_scan = sum(p.stat().st_size for p in seq.rglob("000000.*"))
    est = P.scan_bytes(sensor_for_spec(test_spec).rays_per_sweep)
    assert per_scan <= est <= 2.5 * per_scan, (per_scan, est)


def test_check_free_space_names_the_folder_and_sizes(tmp_path, monkeypatch):
    monkeypatch.setattr(shutil, "disk_usage", lambda p: Usage(2**40, 0, 3 * 2**20))
    P.check_free_space(tmp_path / "a" / "b", 2 * 2**20, "x")  # fits
    with pytest.raises(UserError) as e:
        P.check_free_space(tmp_path / "a" / "b", 5 * 2**30, "12 images")
    assert str(e.value) == f"--out: this run writes about 5.0 GiB (12 images) but {tmp_path} has 3.0 MiB free"


# -- through the command line: refused in one line, quickly, before anything exists ------------------------------


def _refused(capsys, argv, out: Path, plan_needs_scene: bool = False) -> str:
    """Run ``argv``: one line, exit 2, nothing written, and refused before any work -- before the scene is
    built or, where the plan itself needs the town (``generate`` counts the sweeps of the drive through its
    traffic), before anything is scanned or rendered. Doing that work fails the run here, so a refusal that
    came only after it cannot pass."""
    capsys.readouterr()
    work = AssertionError("work was done before the plan was refused")
    targets = (["generator.jobs.lidar_sequence.Scanner", "generator.jobs.dispatch.run_tasks"] if plan_needs_scene
               else ["generator.layout.assemble.build_scene", "generator.layout.build_scene"])
    with contextlib.ExitStack() as stack:
        for target in targets:
            stack.enter_context(mock.patch(target, side_effect=work))
        rc = cli.main(argv)
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and "Traceback" not in err, err
    assert not out.exists()
    return err


@pytest.mark.parametrize("extra, message", [
    (["--frames", "1000001"], "--frames: must be an integer in 1..1000000, got '1000001'"),
    (["--frames", "99999999999999999999999"], "--frames: must be an integer in 1..1000000"),
    (["--workers", "257"], "--workers: must be an integer in 1..256"),
])
def test_generate_refuses_an_absurd_plan_at_once(tmp_path, capsys, extra, message):
    out = tmp_path / "ds"
    err = _refused(capsys, ["generate", SPEC, "--config", "test", "--out", str(out), *extra], out)
    assert message in err, err


def test_render_frame_numbers_stay_six_digits(tmp_path, capsys):
    out = tmp_path / "ds"
    err = _refused(
        capsys, ["render", SPEC, "--config", "test", "--out", str(out), "--first", "999999", "--frames", "2"], out
    )
    assert "frame 1000000 planned" in err


def test_local_workers_beyond_the_cores_are_refused(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(os, "cpu_count", lambda: 2)
    out = tmp_path / "ds"
    err = _refused(capsys, ["render", SPEC, "--config", "test", "--out", str(out), "--workers", "3"], out)
    assert "--workers: 3 local workers but this machine has 2 cores" in err


def test_disk_too_small_is_refused_before_any_work(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(shutil, "disk_usage", lambda p: Usage(2**30, 0, 2**20))
    out = tmp_path / "ds"
    err = _refused(capsys, ["lidar", SPEC, "--out", str(out), "--frames", "1000"], out)  # no scene is built
    assert err.startswith("urbangen lidar: --out: this run writes about ") and f"but {tmp_path} has 1.0 MiB free" in err
    err = _refused(capsys, ["render", SPEC, "--config", "preview", "--out", str(out), "--frames", "10"], out)
    assert "(10 images at 640x360)" in err
    err = _refused(capsys, ["generate", SPEC, "--config", "test", "--out", str(out), "--frames", "3"], out,
                   plan_needs_scene=True)
    # 3 frames 6 m apart at 8 m/s are 1.5 s of drive: 16 sweeps at 10 Hz, a stereo pair every 10th
    assert "36 images and 2 stereo pairs" in err and "16 scans" in err


def test_a_resumed_plan_is_checked_merged(tmp_path, capsys):
    """A rerun extends the plan (union of frames and variants): the union must fit the frame numbers."""
    from generator.spec import load_spec
    from generator.spec.render import load_render_config

    out = tmp_path / "ds"
    out.mkdir()
    manifest = {
        "spec_hash": load_spec(SPEC).spec_hash,
        "render_config": {"config_hash": load_render_config("test").config_hash},
        "plan": {"frame_ranges": [[999_998, 1_000_000]], "combos": [["day", "clear"]], "sequence": "00"},
        "finished": {"images": 0},
        "runs": [],
    }
    (out / "manifest.json").write_text(json.dumps(manifest))
    before = sorted(p.name for p in out.iterdir())
    capsys.readouterr()
    rc = cli.main(["generate", SPEC, "--config", "test", "--out", str(out), "--frames", "1", "--variants", "night:rain",
                   "--plan-only"])
    err = capsys.readouterr().err
    # the merged plan: frames 0, 999 998, 999 999 x (day clear, night rain), a drive far too long for the disk
    assert rc == 2 and "--out: this run writes about" in err and "(6 images and" in err, err
    assert sorted(p.name for p in out.iterdir()) == before


@pytest.mark.parametrize("extra, message", [
    (["--ray-address", "127.0.0.1:6379"], "--ray-address: only with --executor ray"),
    (["--executor", "ray", "--ray-address", "127.0.0.1:1"], "--ray-address: cannot reach 127.0.0.1:1"),
    (["--executor", "ray", "--ray-address", "ray://x:99999"], "--ray-address: expected host:port or ray://host:port"),
])
def test_a_ray_cluster_that_cannot_answer_is_found_before_any_work(tmp_path, capsys, extra, message):
    """ray.init on an address nobody listens at waits for minutes: refused in seconds instead."""
    import importlib.util

    if "ray" in extra and importlib.util.find_spec("ray") is None:
        message = "--executor ray needs Ray"
    out = tmp_path / "ds"
    err = _refused(capsys, ["render", SPEC, "--config", "test", "--out", str(out), *extra], out)
    assert message in err, err
