"""How a command ends when the system or urbangen itself fails, and what it leaves behind.

Disk full, read-only or forbidden output, Ctrl-C and an unexpected exception (a bug) in the
middle of writing: each ends with one line and its exit code (2, 2, 130, 70) and the output
folder the run created is gone. Also: OpenLABEL files urbangen did not make from this spec
are never replaced, and ``generate`` checks a resumed folder's manifest before touching it.
"""

from __future__ import annotations

import errno
import json
import os
from pathlib import Path

import pytest

from generator import cli
from kits.paths import ROOT

SPEC = str(ROOT / "scenes" / "test_town.json")


@pytest.fixture
def cached_scene(monkeypatch, test_scene):
    """``build_scene`` returns the session's test town (layout tests need a scene, not a fresh one)."""
    from generator.layout import assemble

    monkeypatch.setattr(assemble, "build_scene", lambda spec: test_scene)


def _run(capsys, argv):
    capsys.readouterr()
    rc = cli.main(argv)
    _, err = capsys.readouterr()
    assert "Traceback" not in err or "-v" in argv, err
    return rc, err


def _fail_second_write(monkeypatch, exc: BaseException):
    """Make the layout command's second file write raise ``exc`` after the first succeeded."""
    from generator.commands import layout

    real, calls = layout.write_bytes, []

    def flaky(path, data):
        calls.append(path)
        if len(calls) == 2:
            if isinstance(exc, OSError):
                raise type(exc)(exc.errno, exc.strerror, str(path))
            raise exc
        real(path, data)

    monkeypatch.setattr(layout, "write_bytes", flaky)


@pytest.mark.parametrize("code, reason", [(errno.ENOSPC, "no space left on device"),
                                          (errno.EDQUOT, "disk quota exceeded"),
                                          (errno.EROFS, "read-only file system"),
                                          (errno.EACCES, "permission denied")])
def test_a_write_refused_by_the_system_is_one_line_and_leaves_nothing(tmp_path, capsys, monkeypatch, cached_scene,
                                                                       code, reason):
    _fail_second_write(monkeypatch, OSError(code, os.strerror(code)))
    out = tmp_path / "new" / "out"
    rc, err = _run(capsys, ["layout", SPEC, "--out", str(out)])
    # the failing file sat in the stage: the message names the output folder the user gave
    assert rc == 2 and err == f"urbangen layout: {out}: {reason}\n", err
    assert not (tmp_path / "new").exists()


def test_a_stage_that_cannot_be_made_leaves_nothing(tmp_path, capsys, monkeypatch, cached_scene):
    from generator import atomic

    def forbidden(prefix, dir):
        raise PermissionError(errno.EACCES, "Permission denied", dir)

    monkeypatch.setattr(atomic.tempfile, "mkdtemp", forbidden)
    out = tmp_path / "out"
    rc, err = _run(capsys, ["layout", SPEC, "--out", str(out)])
    assert rc == 2 and err == f"urbangen layout: {out}: permission denied\n"
    assert list(tmp_path.iterdir()) == []


def test_ctrl_c_is_one_line_exit_130_and_leaves_nothing(tmp_path, capsys, monkeypatch, cached_scene):
    _fail_second_write(monkeypatch, KeyboardInterrupt())
    out = tmp_path / "out"
    rc, err = _run(capsys, ["layout", SPEC, "--out", str(out)])
    assert rc == 130 and err == "urbangen layout: interrupted\n"
    assert not out.exists()


def test_a_bug_is_one_line_exit_70_with_the_traceback_in_a_log(tmp_path, capsys, monkeypatch, cached_scene):
    _fail_second_write(monkeypatch, ZeroDivisionError("secret value 42"))
    monkeypatch.setattr("tempfile.tempdir", str(tmp_path))  # the crash log goes here
    out = tmp_path / "out"
    rc, err = _run(capsys, ["layout", SPEC, "--out", str(out)])
    assert rc == 70 and err.count("\n") == 1 and "internal error (ZeroDivisionError)" in err, err
    assert "secret value" not in err and not out.exists()
    log = Path(err.split("the traceback is in ")[1].split(";")[0])
    assert log.parent == tmp_path and "Traceback" in log.read_text() and "secret value 42" in log.read_text()
    _fail_second_write(monkeypatch, ZeroDivisionError("secret value 42"))
    rc, err = _run(capsys, ["-v", "layout", SPEC, "--out", str(out)])  # -v: the traceback on stderr too
    assert rc == 70 and "Traceback" in err and err.rstrip("\n").splitlines()[-1].startswith("urbangen layout: internal")


def test_argv_and_messages_with_undecodable_bytes_stay_one_line(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    rc, err = _run(capsys, ["validate", "\udcff\x1b[2J\nnext"])  # invalid UTF-8 in argv, as Python sees it
    assert rc == 2 and err.count("\n") == 1 and "\\udcff" in err and "\\x1b" in err and "\\n" in err, err
    assert "must be a UTF-8 path" in err
    rc, err = _run(capsys, ["validate", "\x1b[2J\nnext"])  # controls are fine in a name, escaped in messages
    assert rc == 2 and err == "urbangen validate: \\x1b[2J\\nnext: dataset folder not found\n", err


# -- OpenLABEL: whose file may be replaced ----------------------------------------------------------------------


@pytest.mark.parametrize("content, reason", [
    ({"openlabel": {"metadata": {"urbangen": {"spec_hash": "0" * 64}}}}, "made from another spec"),
    ({"openlabel": {"metadata": {"annotator": "a person, by hand"}}}, "not an OpenLABEL file urbangen made"),
    ("not json at all", "not an OpenLABEL file urbangen made"),
])
def test_openlabel_never_replaces_a_file_it_did_not_make_from_this_spec(tmp_path, capsys, content, reason):
    target = tmp_path / "ds" / "openlabel" / "00.json"
    target.parent.mkdir(parents=True)
    text = content if isinstance(content, str) else json.dumps(content)
    target.write_text(text)
    rc, err = _run(capsys, ["openlabel", SPEC, str(tmp_path / "ds")])
    assert rc == 2 and err.startswith(f"urbangen openlabel: {target}: ") and reason in err, err
    assert target.read_text() == text and sorted(p.name for p in target.parent.iterdir()) == ["00.json"]


def test_openlabel_refuses_a_target_that_is_not_a_file(tmp_path, capsys):
    target = tmp_path / "ds" / "openlabel" / "00.json"
    target.mkdir(parents=True)
    rc, err = _run(capsys, ["openlabel", SPEC, str(tmp_path / "ds")])
    assert rc == 2 and "exists and is a folder" in err, err


# -- generate: the resumed folder is checked before anything is written -----------------------------------------


@pytest.mark.parametrize("manifest, field", [
    ("[1, 2]", "spec_hash"),
    (('{"spec_hash": "x", "render_config": {"config_hash": "y"}, "plan": {"frames": [0, -1], "combos": [], '
      '"sequence": "00"}, "finished": {}}'), "plan.frames"),
    (('{"spec_hash": "x", "render_config": {"config_hash": "y"}, "plan": {"frames": [0], "combos": [["day", "../x"]], '
      '"sequence": "00"}, "finished": {}}'), "plan.combos"),
    (('{"spec_hash": "x", "render_config": {"config_hash": "y"}, "plan": {"frame_ranges": [[5, 2]], "combos": [], '
      '"sequence": "00"}, "finished": {}}'), "plan.frame_ranges"),
    ('{"spec_hash": NaN}', "NaN"),
    ("FIFO", "named pipe"),
])
def test_generate_checks_a_resumed_manifest_before_writing(tmp_path, capsys, manifest, field):
    out = tmp_path / "ds"
    out.mkdir()
    path = out / "manifest.json"
    if manifest == "FIFO":
        os.mkfifo(path)
    else:
        path.write_text(manifest)
    rc, err = _run(capsys, ["generate", SPEC, "--config", "test", "--out", str(out), "--frames", "1"])
    assert rc == 2 and err.startswith(f"urbangen generate: {path}: ") and field in err, err
    assert sorted(p.name for p in out.iterdir()) == ["manifest.json"]


def test_generate_resumed_with_another_spec_is_refused_before_writing(tmp_path, capsys):
    out = tmp_path / "ds"
    out.mkdir()
    (out / "manifest.json").write_text(json.dumps({
        "spec_hash": "0" * 64, "render_config": {"config_hash": "y"}, "finished": {"images": []},
        "plan": {"frames": [0], "combos": [["day", "clear"]], "sequence": "00"}}))
    rc, err = _run(capsys, ["generate", SPEC, "--config", "test", "--out", str(out), "--frames", "1"])
    assert rc == 2 and "made from another spec" in err
    assert sorted(p.name for p in out.iterdir()) == ["manifest.json"]


# -- lidar: cast in a stage, moved in when complete ----------------------------------------------------------------


def _tree(root: Path) -> dict[str, bytes]:
    return {str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def test_lidar_failing_mid_sequence_leaves_the_older_run_as_it_was(tmp_path, capsys, monkeypatch, cached_scene):
    from generator.formats import semantickitti as sk

    out = tmp_path / "ds"

    def argv(frames: int) -> list[str]:
        return ["-q", "lidar", SPEC, "--out", str(out), "--frames", str(frames), "--no-bev", "--threads", "2"]

    assert _run(capsys, argv(2))[0] == 0
    extra = out / "lidar" / "sequences" / "00" / "image_2" / "000000.png"  # a generate dataset's stereo image
    extra.parent.mkdir()
    extra.write_bytes(b"png")
    before = _tree(out)
    real, calls = sk.write_labels, []

    def full_disk(path, *a):
        calls.append(path)
        if len(calls) == 2:
            raise OSError(errno.ENOSPC, "No space left on device", str(path))
        real(path, *a)

    monkeypatch.setattr(sk, "write_labels", full_disk)
    rc, err = _run(capsys, argv(3))
    assert rc == 2 and err == f"urbangen lidar: {out / 'lidar'}: no space left on device\n", err
    assert _tree(out) == before  # no stage, no half sequence, nothing replaced
    monkeypatch.setattr(sk, "write_labels", real)
    assert _run(capsys, argv(1))[0] == 0  # a shorter rerun
    seq = out / "lidar" / "sequences" / "00"
    assert sorted(p.name for p in (seq / "velodyne").iterdir()) == ["000000.bin"]
    assert extra.read_bytes() == b"png" and not list(out.rglob(".tmp-*"))
