"""`urbangen generate` / `validate` / `preview` end to end on the test town (Blender, test preset).

One uninterrupted 2-worker run is the reference; a run killed with SIGKILL and rerun,
and a Ray run, must end with the same files and identical LiDAR bytes.

The reference is made once per test run (:mod:`kits.shared_build`): the tests that read it form one
unit of work; the SIGKILL and the Ray test each make their own run first, on whichever worker is free,
and wait for the reference only to compare.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import OpenEXR
import pytest

from generator.cli import main
from generator.imaging.exr import read_exr
from generator.imaging.paths import image_files, image_path
from kits.generated_town import generate_args, reference_run
from kits.shared_build import SharedBuild

pytestmark = [pytest.mark.blender, pytest.mark.slow]
_args = generate_args  # FRAMES = "2" frames of VARIANTS = "day:clear,night:rain": the counts below


@pytest.fixture(scope="session")
def shared_reference(tmp_path_factory, root) -> SharedBuild:
    """The uninterrupted 2-worker run (:mod:`kits.generated_town`), made when a test first asks for it."""
    return reference_run(tmp_path_factory, root)


@pytest.fixture(scope="module")
def reference(shared_reference) -> Path:
    return shared_reference.path()


def _files(root: Path) -> set[str]:
    return {str(p.relative_to(root)) for p in root.rglob("*") if p.is_file() and p.name != "manifest.json"}


def _lidar_bytes(root: Path) -> dict[str, bytes]:
    seq = root / "lidar" / "sequences"
    return {str(p.relative_to(seq)): p.read_bytes() for p in sorted(seq.rglob("*"))
            if p.is_file() and p.suffix in (".bin", ".label", ".txt")}


def _same_images(a: Path, b: Path) -> None:
    for exr in image_files(a, "*.exr"):
        x, y = read_exr(exr), read_exr(image_path(b, exr.stem, ".exr"))
        assert np.array_equal(x.class_id, y.class_id), exr.name
        assert np.array_equal(x.depth, y.depth), exr.name
        assert np.allclose(x.rgb, y.rgb, atol=1e-3), exr.name


def test_dataset_is_complete_balanced_and_valid(reference, capsys):
    m = json.loads((reference / "manifest.json").read_text())
    assert m["finished"] == {**m["finished"], "lidar": True, "openlabel": True, "stats": True}
    assert m["finished"]["images"] == 2 * 2 == len(image_files(reference, "*.exr"))
    counts = {}
    for p in image_files(reference, "*.json"):
        meta = json.loads(p.read_text())
        key = (meta["time_of_day"], meta["weather"]["kind"])
        counts[key] = counts.get(key, 0) + 1
    assert set(counts.values()) == {2} and len(counts) == 2
    assert (reference / "openlabel" / "00.json").exists()
    assert (reference / "stats" / "table2_conditions.csv").exists()
    assert len(list((reference / "lidar/sequences/00/velodyne").glob("*.bin"))) == 9  # 0.8 s of drive at 10 Hz
    capsys.readouterr()
    assert main(["validate", str(reference)]) == 0
    assert "valid: 4 images, 9 scans, 1 OpenLABEL" in capsys.readouterr().out


def test_rerun_skips_finished_work(reference, root, tmp_path, capsys):
    data = tmp_path / "data"  # a copy: the reference is shared with tests running beside this one
    shutil.copytree(reference, data)
    before = {p: p.stat().st_mtime_ns for p in image_files(data, "*.exr")}
    assert main(["-q", *_args(root, data, "--workers", "2")]) == 0
    assert "nothing left to render" in capsys.readouterr().out
    assert before == {p: p.stat().st_mtime_ns for p in image_files(data, "*.exr")}


def test_preview_sheets(reference, tmp_path):
    from PIL import Image

    data = tmp_path / "data"
    shutil.copytree(reference, data)
    assert main(["preview", str(data)]) == 0
    sheet = Image.open(data / "preview" / "000000.png")
    assert sheet.height >= 360 and sheet.width > 2 * sheet.height
    assert (data / "preview" / "000000_variants.png").exists()


def _rewrite_exr(path: Path, fn) -> None:
    with OpenEXR.File(str(path), separate_channels=True) as f:
        header = {k: v for k, v in f.header().items() if k in ("compression", "type") or k.startswith("urbangen.")}
        ch = {k: np.ascontiguousarray(v.pixels.copy()) for k, v in f.channels().items()}
    fn(ch)
    with OpenEXR.File(header, ch) as f:
        f.write(str(path))


def _truncate_bin(d):
    p = d / "lidar/sequences/00/velodyne/000001.bin"
    p.write_bytes(p.read_bytes()[:-5])


def _label_out_of_table(d):
    p = d / "lidar/sequences/00/labels/000000.label"
    lab = np.fromfile(p, np.uint32)
    lab[:10] = 77
    lab.tofile(p)


def _drop_metadata_field(d):
    p = image_path(d, "000001_night_rain", ".json")
    meta = json.loads(p.read_text())
    del meta["camera"]
    p.write_text(json.dumps(meta))


def _non_binary_mask(d):
    _rewrite_exr(image_path(d, "000000_day_clear", ".exr"), lambda ch: ch["mask.road.V"].__setitem__((0, 0), 0.5))


def _missing_channel(d):
    _rewrite_exr(image_path(d, "000001_day_clear", ".exr"), lambda ch: ch.pop("mask.car.V"))


@pytest.mark.parametrize("fault,expected", [
    (_truncate_bin, "velodyne/000001.bin: size"),
    (_label_out_of_table, "label ids [77] are not in the label table"),
    (_drop_metadata_field, "000001_night_rain.json: (top level): 'camera' is a required property"),
    (_non_binary_mask, "000000_day_clear.exr: mask channels are not binary"),
    (_missing_channel, "000001_day_clear.exr: missing channel(s) mask.car"),
])
def test_validate_catches_each_fault(reference, tmp_path, capsys, fault, expected):
    broken = tmp_path / "broken"
    shutil.copytree(reference, broken)
    fault(broken)
    capsys.readouterr()
    assert main(["validate", str(broken)]) == 1
    err = capsys.readouterr().err
    assert expected in err
    assert "1 problem(s)" in err


def test_sigkill_then_resume_gives_the_uninterrupted_files(shared_reference, root, tmp_path):
    out = tmp_path / "killed"
    cmd = [sys.executable, "-m", "generator.cli", "-q", *_args(root, out, "--workers", "2")]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 300   # killed once half the images are made: the resume has the other half to do
    while time.time() < deadline and len(image_files(out, "*.json")) < 2 if out.exists() else True:
        if proc.poll() is not None:
            pytest.fail("generate finished before it could be killed")
        time.sleep(0.05)
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    time.sleep(1.5)  # the workers' watchdog notices the dead parent and exits
    done = len(image_files(out, "*.json"))
    assert 0 < done < 4, "the kill should land mid-run"
    assert main(["-q", *_args(root, out, "--workers", "2")]) == 0
    reference = shared_reference.path()
    assert _files(out) == _files(reference)
    assert _lidar_bytes(out) == _lidar_bytes(reference)
    _same_images(out, reference)
    assert main(["validate", str(out)]) == 0


def test_ray_executor_equals_local(shared_reference, root, tmp_path, monkeypatch):
    pytest.importorskip("ray")
    # Ray runs its workers at nice 15: beside the other pytest worker (nice 0) they would get almost no CPU
    monkeypatch.setenv("RAY_worker_niceness", "0")
    out = tmp_path / "ray"
    assert main(["-q", *_args(root, out, "--workers", "2", "--executor", "ray")]) == 0
    reference = shared_reference.path()
    assert _files(out) == _files(reference)
    assert _lidar_bytes(out) == _lidar_bytes(reference)
    _same_images(out, reference)
