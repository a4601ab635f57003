"""``generate`` at scale, with stand-in tasks (no Blender): a million-image plan is accepted and its
bookkeeping holds; a parent killed with SIGKILL anywhere resumes to the uninterrupted run's bytes.

The end-to-end run with real renders is ``tests/test_generate.py`` (Blender).
"""

from __future__ import annotations

import json
import shutil
import signal
import subprocess
from collections import namedtuple
from pathlib import Path

import pytest

from generator.cli import main
from generator.jobs.frameset import FrameSet
from generator.jobs.journal import Journal, combo_mask
from generator.jobs.plan import make_plan
from kits.shared_build import SharedBuild
from kits.stand_in_run import COMBOS, forked, run, spec_with_towns

Usage = namedtuple("Usage", "total used free")
FRAMES, EVERY = "6", "3"  # two towns of three frames


def _kit(out: Path, kill_at: str | None = None) -> subprocess.CompletedProcess:
    """The stand-in run in its own process (``kits.stand_in_run``), one a test can kill: forked from this
    one, so each of the ~20 kills below does not start Python and import the generator again (~1.2 s each)."""
    code, said = forked(out, int(FRAMES), int(EVERY), kill_at)
    return subprocess.CompletedProcess([], code, said, said)


def _files(root: Path) -> dict[str, bytes]:
    return {str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*"))
            if p.is_file() and p.name != "manifest.json"}


def _manifest(root: Path) -> dict:
    m = json.loads((root / "manifest.json").read_text())
    return {k: v for k, v in m.items() if k not in ("created", "updated", "runs")}


def _resume(out: Path) -> None:
    """The same run, uninterrupted, in this process (a resume is about the folder, not the process)."""
    run(out, int(FRAMES), int(EVERY))


# made once per test run (kits.shared_build) and read by the kill tests below on both pytest-xdist workers,
# so they spread over both instead of queueing on the one that would hold a module-scoped reference
@pytest.fixture(scope="session")
def reference(tmp_path_factory):
    def build(folder: Path) -> None:
        assert _kit(folder / "ref").returncode == 0

    return SharedBuild(tmp_path_factory, "standin_reference", build).path() / "ref"


def test_a_stand_in_run_records_every_item_once(reference):
    files = _files(reference)
    assert sum(k.startswith("images/0000/") for k in files) == 6 * 2
    assert sorted(k for k in files if k.startswith("stand-in/")) == [
        "stand-in/00.lidar", "stand-in/00.motion", "stand-in/00.openlabel", "stand-in/01.lidar", "stand-in/01.motion",
        "stand-in/01.openlabel",
        "stand-in/dataset.label_config", "stand-in/dataset.stats"]
    assert [k for k in files if k.startswith("journal/")] == ["journal/merged.log"]  # compacted at the end
    lines = files["journal/merged.log"].decode().splitlines()
    assert [ln.split("\t")[0] for ln in lines] == [
        "urbangen-journal 1", "frames 0-5 day:clear,night:rain", "stereo 00 0", "stereo 01 0",
        "town 00 lidar 0-2 sweeps=7", "town 00 motion 0-2", "town 00 openlabel 0-2", "town 01 lidar 3-5 sweeps=7",
        "town 01 motion 3-5", "town 01 openlabel 3-5",
        *(f"dataset {p} {lines[-1].split()[2]}" for p in ("label_config", "stats"))]
    m = json.loads((reference / "manifest.json").read_text())
    assert m["manifest_version"] == 2 and m["plan"]["frame_ranges"] == [[0, 6]] and m["plan"]["images"] == 12
    assert m["finished"] == {"images": 12, "frames": 6, "frame_ranges": [[0, 6]], "stereo": 2,
                             "towns": {"count": 2, "lidar": 2, "motion": 2, "openlabel": 2}, "lidar": True,
                             "motion": True, "openlabel": True,
                             "stats": True, "journal": "journal/"}


def test_a_rerun_reads_the_journal_not_the_files(reference, tmp_path, monkeypatch):
    from generator.jobs import resume as R
    from generator.jobs.generate import GenerateOptions, run_generate
    from generator.spec import load_spec
    from generator.spec.render import load_render_config

    out = tmp_path / "again"
    shutil.copytree(reference, out)
    before = {p: p.stat().st_mtime_ns for p in out.rglob("*") if p.is_file() and p.name != "manifest.json"}

    def no_lookups(*a, **k):
        raise AssertionError("a resume looked an image up on disk")

    monkeypatch.setattr(R, "find_image", no_lookups)
    spec = load_spec(spec_with_towns(int(EVERY), tmp_path / "spec.json"))
    run = run_generate(spec, load_render_config("test"),
                       GenerateOptions(out, make_plan(int(FRAMES), combos=COMBOS), 2, stand_in=True))
    assert run["tasks"] == 0
    assert before == {p: p.stat().st_mtime_ns for p in out.rglob("*") if p.is_file() and p.name != "manifest.json"}


def test_a_dataset_from_before_the_journal_resumes_from_its_files(reference, tmp_path):
    """A version 1 manifest (every frame and image listed) and no journal: finished images are looked up once,
    not made again; the journal is written; the run ends with the files of an uninterrupted one."""
    from generator.jobs.images import image_name

    out = tmp_path / "v1"
    shutil.copytree(reference, out)
    shutil.rmtree(out / "journal")
    m = json.loads((out / "manifest.json").read_text())
    m["manifest_version"] = 1
    m["plan"] = {"frames": list(range(6)), "combos": [list(c) for c in COMBOS], "sequence": "00", "images": 12}
    m["finished"] = {"images": [image_name(k, t, w) for k in range(6) for t, w in COMBOS], "lidar": True,
                     "openlabel": True, "stats": True, "stereo": ["00/0", "01/0"]}
    (out / "manifest.json").write_text(json.dumps(m))
    images = {p: p.stat().st_mtime_ns for p in (out / "images").rglob("*.json")}
    _resume(out)
    assert images == {p: p.stat().st_mtime_ns for p in (out / "images").rglob("*.json")}  # none made again
    assert _files(out) == _files(reference)
    assert json.loads((out / "manifest.json").read_text())["finished"] == _manifest(reference)["finished"]


def test_a_journal_left_without_its_manifest_is_not_trusted(reference, tmp_path):
    """A folder with a journal but no manifest is a new dataset: its journal (of another run) is dropped."""
    out = tmp_path / "orphan"
    shutil.copytree(reference / "journal", out / "journal")
    _resume(out)
    assert _files(out) == _files(reference)


def _killed_then_resumed(reference: Path, tmp_path: Path, point: str) -> None:
    out = tmp_path / "killed"
    first = _kit(out, point)
    assert first.returncode == -signal.SIGKILL, (point, first.returncode, first.stderr[-2000:])
    _resume(out)
    assert _files(out) == _files(reference), point
    assert _manifest(out) == _manifest(reference), point


# the first item, a torn line mid-run, the compaction of a finished run, the manifest written at the start
@pytest.mark.parametrize("point", ["append:1", "torn:7", "compact:1", "manifest:1"])
def test_sigkill_at_a_point_of_the_bookkeeping_then_resume_gives_the_same_bytes(reference, tmp_path, point):
    _killed_then_resumed(reference, tmp_path, point)


@pytest.mark.slow
@pytest.mark.parametrize("point", [f"append:{n}" for n in range(2, 15)] + [f"torn:{n}" for n in (1, 4, 10, 14)]
                         + ["manifest:2"])
def test_sigkill_anywhere_in_the_bookkeeping_then_resume_gives_the_same_bytes(reference, tmp_path, point):
    """Before every journal line (14 items), torn lines, after both manifest writes (start, end), in the compaction."""
    _killed_then_resumed(reference, tmp_path, point)


# -- a million images ----------------------------------------------------------------------------------------------


@pytest.fixture
def towns_spec(tmp_path):
    return spec_with_towns(100, tmp_path / "towns.json")


def test_a_million_image_plan_is_accepted_when_the_disk_allows_it(towns_spec, tmp_path, capsys, monkeypatch):
    """83 334 frames x 12 variants in towns of 100 frames: 834 towns, sequences 00..833; planned, checked,
    nothing written. The same plan on a smaller disk is refused in one line."""
    out = tmp_path / "million"
    argv = ["generate", str(towns_spec), "--config", "test", "--out", str(out), "--frames", "83334", "--plan-only"]
    monkeypatch.setattr(shutil, "disk_usage", lambda p: Usage(2**50, 0, 2**50))
    capsys.readouterr()
    assert main(argv) == 0
    said = capsys.readouterr().out
    assert "83334 frames, 1000008 images, 834 town(s), LiDAR sequence(s) 00..833" in said, said
    assert not out.exists()
    monkeypatch.setattr(shutil, "disk_usage", lambda p: Usage(2**40, 0, 2**40))
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "this run writes about" in err and "1000008 images" in err and "of 834 towns" in err
    assert "1.0 TiB free" in err
    assert not out.exists()


def test_the_bookkeeping_of_a_million_image_plan(towns_spec, tmp_path):
    """Resuming a million-image plan with one frame left: the survey finds the one town, its one frame, and
    issues one render task for it; the manifest's summary stays a few ranges."""
    from generator.jobs import manifest as mf
    from generator.jobs.schedule import RunSetup, RunSource
    from generator.jobs.town_job import TOWN_PRODUCTS
    from generator.jobs.towns import TownPlan
    from generator.spec import load_spec
    from generator.spec.render import load_render_config

    spec, plan = load_spec(towns_spec), make_plan(83_334)
    towns = TownPlan(spec, plan)
    journal = Journal(tmp_path)
    mask_frames = FrameSet.span(0, 83_334)
    journal.ledger.add_frames(FrameSet([(0, 4_321), (4_322, 83_334)]), combo_mask(plan.combos))
    for i in towns.indices:
        journal.ledger.add_stereo(towns.sequence(i), 0)  # a one-sweep drive: one stereo pair
        for product in TOWN_PRODUCTS:
            journal.ledger.add_town(towns.sequence(i), product.name, _text(towns.frames(i)),
                                    {"sweeps": "1"} if product.name == "lidar" else {})
    source = RunSource(RunSetup(spec, load_render_config("test"), tmp_path, plan, towns, journal, 2, stand_in=True))
    tasks = source.ready()
    assert [t.kind for t in tasks] == ["render"] and list(tasks[0].job.job.frames[0]) == [4_321]
    assert tasks[0].job.job.out == str(tmp_path) and source.total() == 1 + 2  # the frame, then the dataset's two
    summary = mf.finished_summary(plan, journal.ledger, len(towns), dict(source.done_products), False)
    assert summary["images"] == 1_000_008 - 12 and summary["frame_ranges"] == [[0, 4_321], [4_322, 83_334]]
    assert summary["towns"] == {"count": 834, "lidar": 834, "motion": 834, "openlabel": 834}
    assert len(mask_frames) == 83_334


def _text(frames):
    from generator.jobs.journal import frames_text

    return frames_text(frames)
