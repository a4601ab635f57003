"""generator.safeload: every check of the hardened reader, one line each, fast, never echoing content."""

from __future__ import annotations

import json
import math
import os
import time
from pathlib import Path

import numpy as np
import pytest

from generator import safeload
from generator.errors import SpecError, UserError
from generator.spec import load_spec
from generator.spec.render import load_render_config
from kits.paths import ROOT

SECRET = "hunter2-TOP-SECRET-do-not-print"


def _write(path: Path, data: str | bytes) -> Path:
    (path.write_bytes if isinstance(data, bytes) else path.write_text)(data)
    return path


#: A hostile input must be refused, not waited on: without the guards a FIFO blocks for ever, /dev/zero
#: reads until memory runs out and a billion laughs expands for minutes. This bound tells those apart from
#: a refusal on a loaded machine; it is not a speed measurement (that is bench/'s job).
HANG_GUARD_S = 30.0


def _refused(fn, *args, match: str | None = None, **kw) -> str:
    """Call ``fn``; it must raise one UserError line without hanging. Returns the message."""
    t0 = time.perf_counter()
    with pytest.raises(UserError) as e:
        fn(*args, **kw)
    elapsed = time.perf_counter() - t0
    msg = str(e.value)
    assert "\n" not in msg, msg
    assert elapsed < HANG_GUARD_S, f"took {elapsed:.2f} s: {msg}"
    if match is not None:
        assert match in msg, msg
    return msg


def _billion_laughs(levels: int = 9, width: int = 9) -> str:
    lines = ['a: &a ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]']
    for i in range(1, levels + 1):
        name, prev = chr(ord("a") + i), chr(ord("a") + i - 1)
        lines.append(f"{name}: &{name} [{', '.join('*' + prev for _ in range(width))}]")
    return "\n".join(lines) + "\n"


# -- files: kind, size, errors --------------------------------------------------------------------------------


def test_reads_a_regular_file(tmp_path):
    p = _write(tmp_path / "a.txt", "hello")
    assert safeload.read_bytes(p) == b"hello"
    assert safeload.read_text(p) == "hello"


def test_missing_file(tmp_path):
    msg = _refused(safeload.read_bytes, tmp_path / "nope.json")
    assert msg == f"{tmp_path / 'nope.json'}: file not found"


def test_source_and_field_name_the_file(tmp_path):
    msg = _refused(safeload.read_bytes, tmp_path / "nope.yaml", source="spec.json", field="sensors.lidar.sensor_file")
    assert msg == "spec.json: sensors.lidar.sensor_file: file not found"


def test_directory(tmp_path):
    _refused(safeload.read_bytes, tmp_path, match="is a folder, expected a regular file")


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_fifo_is_refused_without_blocking(tmp_path):
    fifo = tmp_path / "pipe.json"
    os.mkfifo(fifo)  # no writer: opening it for reading in blocking mode would hang forever
    _refused(safeload.read_bytes, fifo, match="named pipe")
    _refused(load_spec, fifo, match="named pipe")


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="needs /dev/zero")
def test_endless_device_is_refused_at_once():
    _refused(safeload.read_bytes, "/dev/zero", match="character device")
    _refused(load_render_config, "/dev/zero", match="/dev/zero: is a character device")


def test_socket_is_refused(tmp_path):
    import socket

    path = tmp_path / "s.sock"
    with socket.socket(socket.AF_UNIX) as s:
        try:
            s.bind(str(path))
        except OSError:
            pytest.skip("cannot bind a unix socket here")
        _refused(safeload.read_bytes, path, match="socket")


def test_symlink_loop(tmp_path):
    loop = tmp_path / "loop.json"
    loop.symlink_to(loop)
    _refused(safeload.read_bytes, loop, match="symlink loop")
    _refused(load_spec, loop, match="symlink loop")


@pytest.mark.skipif(hasattr(os, "geteuid") and os.geteuid() == 0, reason="root reads everything")
def test_permission_denied(tmp_path):
    p = _write(tmp_path / "locked.json", "{}")
    p.chmod(0)
    try:
        _refused(safeload.read_bytes, p, match="permission denied")
    finally:
        p.chmod(0o644)


def test_oversized_file_is_refused_before_reading(tmp_path):
    p = tmp_path / "big.json"
    with open(p, "wb") as f:  # sparse: large on paper, nothing to read
        f.truncate(safeload.MAX_DOCUMENT_BYTES + 1)
    msg = _refused(safeload.read_bytes, p, match="file too large")
    assert "4.0 MiB" in msg
    _refused(load_spec, p, match="file too large")
    _refused(safeload.read_bytes, _write(tmp_path / "small", b"x" * 11), max_bytes=10, match="file too large")
    assert safeload.read_bytes(tmp_path / "small", max_bytes=11) == b"x" * 11


def test_file_that_lies_about_its_size_is_cut_off():
    # /proc files report size 0 but have content: the read stops at max_bytes + 1.
    if not os.path.exists("/proc/self/status"):
        pytest.skip("needs /proc")
    _refused(safeload.read_bytes, "/proc/self/status", max_bytes=8, match="file too large")


def test_nul_byte_and_newline_in_a_path_stay_one_line(tmp_path):
    _refused(safeload.read_bytes, "a\0b.json", match="NUL byte")
    msg = _refused(safeload.read_bytes, str(tmp_path / "two\nlines.json"), match="file not found")
    assert "two\\nlines.json" in msg


def test_not_utf8_names_the_byte_not_the_content(tmp_path):
    p = _write(tmp_path / "latin1.yaml", f"name: {SECRET}\nx: caf\xe9\n".encode("latin-1"))
    msg = _refused(safeload.read_text, p)
    assert msg == f"{p}: not UTF-8 text (byte {len(SECRET) + 13})"
    assert SECRET not in msg


def test_byte_order_mark_is_dropped(tmp_path):
    p = _write(tmp_path / "bom.json", "\ufeff{\"a\": 1}".encode("utf-8"))
    assert safeload.load_json(p) == {"a": 1}


# -- JSON --------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("text", [
    "[" * 100_000 + "]" * 100_000,
    '{"a":' * 100_000 + "1" + "}" * 100_000,
    "[" * 100_000,  # unclosed
])
def test_json_deep_nesting_is_refused_quickly(text):
    _refused(safeload.parse_json, text, "deep.json", match="nested deeper than 64 levels")


def test_json_depth_limit_is_exact_and_ignores_brackets_in_strings():
    assert safeload.parse_json("[" * 64 + "]" * 64, "x.json")
    _refused(safeload.parse_json, "[" * 65 + "]" * 65, "x.json", match="nested deeper")
    assert safeload.parse_json('["' + "[" * 500 + '", "\\"{{{{"]', "x.json") == ["[" * 500, '"{{{{']


def test_json_recursion_error_is_caught_even_without_the_prescan():
    _refused(safeload.parse_json, "[" * 100_000 + "]" * 100_000, "x.json", max_depth=10**9, match="nested deeper")


@pytest.mark.parametrize("text, match", [
    ('{"a": 1, "a": 2}', "duplicate key 'a'"),
    ('{"a": NaN}', "NaN is not a valid JSON number"),
    ('{"a": Infinity}', "Infinity is not a valid JSON number"),
    ('{"a": -Infinity}', "-Infinity is not a valid JSON number"),
    ('{"a": {"b": [1, 1e400]}}', "a.b[1]: must be a finite number, got inf"),
    ('{"a": -1e400}', "a: must be a finite number, got -inf"),
    ('{"a": ' + "9" * 400 + "}", "a: must be a finite number, got an integer with about 400 digits"),
    ('{"a": ' + "9" * 100_000 + "}", "a: must be a finite number"),
    ('{"a": 1,}', "invalid JSON at line 1 column 9"),
])
def test_json_strictness(text, match):
    _refused(safeload.parse_json, text, "x.json", match=match)


def test_json_node_budget():
    _refused(safeload.parse_json, json.dumps(list(range(30_000))), "x.json", match="more than 20000 values")
    assert len(safeload.parse_json(json.dumps(list(range(30_000))), "x.json", max_nodes=40_000)) == 30_000


def test_json_pathological_strings_stay_linear():
    # Many quotes/backslashes and no terminator: the depth pre-scan must not go quadratic.
    _refused(safeload.parse_json, '"\\' * 1_000_000, "x.json", match="Unterminated string")
    _refused(safeload.parse_json, '"' + "\\" * 2_000_000, "x.json", match="Unterminated string")


def test_json_error_never_quotes_the_text():
    msg = _refused(safeload.parse_json, '{"a": "' + SECRET + '\x01"}', "x.json", match="invalid JSON at line 1")
    assert SECRET not in msg


# -- YAML --------------------------------------------------------------------------------------------------------


def test_yaml_plain_document():
    assert safeload.parse_yaml("a: 1\nb: [x, 2.5, null, true]\nd: 2020-01-01\n", "x.yaml") == {
        "a": 1, "b": ["x", 2.5, None, True], "d": "2020-01-01"}  # dates stay strings, as in JSON


@pytest.mark.parametrize("text", [
    "[" * 100_000 + "]" * 100_000,
    "{a: " * 100_000 + "1" + "}" * 100_000,
    "".join(" " * i + "- \n" for i in range(3000)),
    "".join(" " * i + "a:\n" for i in range(3000)),
])
def test_yaml_deep_nesting_is_refused_quickly(text):
    _refused(safeload.parse_yaml, text, "deep.yaml", match="nested deeper than 64 levels")


def test_yaml_billion_laughs_fails_fast():
    msg = _refused(safeload.parse_yaml, _billion_laughs(), "lol.yaml")
    assert "values (aliases expanded)" in msg or "aliases" in msg


def test_yaml_alias_budget():
    ok = "a: &a 1\nb: [" + ", ".join(["*a"] * 100) + "]\n"
    assert len(safeload.parse_yaml(ok, "x.yaml")["b"]) == 100
    _refused(safeload.parse_yaml, ok.replace("]", ", *a]"), "x.yaml", match="more than 100 aliases")


def test_yaml_recursive_alias_and_depth_through_aliases():
    _refused(safeload.parse_yaml, "a: &a [1, *a]\n", "x.yaml", match="recursive alias")
    deep = "a: &a " + "[" * 40 + "]" * 40 + "\nb: " + "[" * 30 + "*a" + "]" * 30 + "\n"
    _refused(safeload.parse_yaml, deep, "x.yaml", match="nested deeper than 64 levels (through an alias)")


def test_yaml_merge_keys_still_work():
    doc = safeload.parse_yaml("base: &b {x: 1, y: 2}\nd:\n  <<: *b\n  x: 3\n", "x.yaml")
    assert doc["d"] == {"x": 3, "y": 2}


@pytest.mark.parametrize("text, match", [
    ("a: 1\nb: 2\na: 3\n", "line 3 column 1: duplicate key 'a'"),
    ("top:\n  k: 1\n  k: 1\n", "line 3 column 3: duplicate key 'k'"),
    ("a: {x: 1, x: 2}\n", "duplicate key 'x'"),
])
def test_yaml_duplicate_keys(text, match):
    _refused(safeload.parse_yaml, text, "dup.yaml", match=match)


@pytest.mark.parametrize("text, match", [
    ("a: .nan\n", "a: must be a finite number, got nan"),
    ("a: [1, .inf]\n", "a[1]: must be a finite number, got inf"),
    ("a: {b: -.inf}\n", "a.b: must be a finite number, got -inf"),
    ("a: 1.0e+999\n", "a: must be a finite number, got inf"),
    ("a: " + "9" * 400 + "\n", "a: must be a finite number, got an integer with about 400 digits"),
    ("a: 0x" + "f" * 3990 + "\n", "a: must be a finite number, got an integer with about 4805 digits"),
    ("a: " + "9" * 5000 + "\n", "integer with more than 4000 digits"),
    ("a: " + "1:" * 3000 + "1\n", "integer with more than 4000 digits"),  # sexagesimal: quadratic to convert
])
def test_yaml_numbers_must_be_finite(text, match):
    _refused(safeload.parse_yaml, text, "n.yaml", match=match)


@pytest.mark.parametrize("text, match", [
    ("a: !!set {x, y}\n", "unsupported tag 'set'"),
    ("a: !!binary aGVsbG8=\n", "unsupported tag 'binary'"),
    ("a: !!omap [x: 1]\n", "unsupported tag 'omap'"),
    ("a: !!python/object/apply:os.system ['echo pwned']\n", "could not determine a constructor"),
    ("1: one\n", "a key must be a string, got int"),
    ("? [a]\n: 1\n", "a key must be a string"),
    ("a: 1\n---\nb: 2\n", "expected a single document in the stream, but found another document"),
])
def test_yaml_only_plain_data(text, match):
    _refused(safeload.parse_yaml, text, "t.yaml", match=match)


def test_yaml_numeric_keys_when_asked():
    doc = safeload.parse_yaml("0: unlabeled\n10: car\n", "labels.yaml", string_keys=False)
    assert doc == {0: "unlabeled", 10: "car"}


@pytest.mark.parametrize("text", [
    f"name: x\n{SECRET}\nrate: 1\n",                        # a line without a colon
    f"name: x\nrate: 1: {SECRET}\n",                       # mapping values not allowed
    f"name: x\nvalue: !{SECRET} 3\n",                      # unknown tag named after the secret
    f"name: x\nvalue: *{SECRET}\n",                        # undefined alias
    f"name: '{SECRET}\n",                                  # unterminated quote
    f"name: [{SECRET}\n",                                  # unterminated flow
    f"name: x\n\t{SECRET}: 1\n",                           # tab indentation
    f"name: \"{SECRET}\\q\"\n",                            # bad escape
    f"name: x\x00{SECRET}\n",                              # unprintable character
])
def test_yaml_errors_never_echo_the_content(tmp_path, text):
    p = _write(tmp_path / "bad.yaml", text)
    msg = _refused(safeload.load_yaml, p, match=f"{p}: invalid YAML")
    assert SECRET not in msg and "TOP-SECRET" not in msg and "hunter2" not in msg, msg
    assert "line " in msg and " column " in msg, msg


def test_yaml_size_limit(tmp_path):
    p = tmp_path / "big.yaml"
    with open(p, "wb") as f:
        f.truncate(safeload.MAX_YAML_BYTES + 1)
    _refused(safeload.load_yaml, p, match="file too large")


# -- parsed data ------------------------------------------------------------------------------------------------


def test_check_finite_walks_iteratively_and_names_the_field():
    deep: list = [1.0]
    for _ in range(50_000):
        deep = [deep]
    safeload.check_finite(deep, "x")  # no RecursionError
    _refused(safeload.check_finite, deep, "x", max_depth=64, match="nested deeper than 64 levels")
    _refused(safeload.check_finite, {"a": [{"b": np.float32("nan")}]}, "x.json",
             match="x.json: a[0].b: must be a finite")
    _refused(safeload.check_finite, float("inf"), "x.json", match="x.json: (top level): must be a finite number")
    cyclic: list = [1]
    cyclic.append(cyclic)
    safeload.check_finite(cyclic, "x")  # terminates


def test_field_path_escapes_hostile_keys():
    assert safeload.field_path(["town", "blocks_x"]) == "town.blocks_x"
    assert safeload.field_path(["lasers", 3, "ring"]) == "lasers[3].ring"
    assert safeload.field_path(["a\nb", "\ud800"]) == "a\\nb.\\ud800"
    assert len(safeload.field_path(["k" * 1000])) == 64


# -- paths named inside files -----------------------------------------------------------------------------------


def test_confined_path(tmp_path):
    spec_dir = tmp_path / "specs"
    (spec_dir / "sub").mkdir(parents=True)
    _write(tmp_path / "outside.yaml", SECRET)
    args = ("specs/s.json", "sensors.lidar.sensor_file")
    assert safeload.confined_path(spec_dir, "sub/../x.yaml", *args) == (spec_dir / "x.yaml").resolve()
    assert safeload.confined_path(spec_dir, "sub/x.yaml", *args) == (spec_dir / "sub" / "x.yaml").resolve()
    for bad, match in [("/etc/passwd", "got an absolute path"), (str(tmp_path / "outside.yaml"), "absolute path"),
                       ("../outside.yaml", "must stay inside the spec's folder"),
                       ("sub/../../outside.yaml", "must stay inside"), ("", "empty"), ("a\0b", "NUL byte")]:
        msg = _refused(safeload.confined_path, spec_dir, bad, *args, match=match)
        assert msg.startswith("specs/s.json: sensors.lidar.sensor_file: ") and SECRET not in msg
    (spec_dir / "link.yaml").symlink_to(tmp_path / "outside.yaml")
    (spec_dir / "linkdir").symlink_to(tmp_path)
    _refused(safeload.confined_path, spec_dir, "link.yaml", *args, match="must stay inside")
    _refused(safeload.confined_path, spec_dir, "linkdir/outside.yaml", *args, match="must stay inside")
    (spec_dir / "inner.yaml").symlink_to(spec_dir / "sub")  # a link that stays inside is fine
    assert safeload.confined_path(spec_dir, "inner.yaml", *args) == (spec_dir / "sub").resolve()


def test_confined_path_from_a_linked_spec_folder(tmp_path):
    real = tmp_path / "real"
    real.mkdir()
    (tmp_path / "alias").symlink_to(real)
    assert safeload.confined_path(tmp_path / "alias", "x.yaml", "s", "f") == real.resolve() / "x.yaml"


# -- tables and arrays -----------------------------------------------------------------------------------------


def test_read_matrix_rows(tmp_path):
    p = _write(tmp_path / "poses.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 5 0 1 0 0 0 0 1 0\n\n")
    m = safeload.read_matrix_rows(p, 12)
    assert m.shape == (2, 12) and m[1, 3] == 5


@pytest.mark.parametrize("text, match", [
    ("1 2 3\n4 5\n", "line 2: expected 3 numbers, got 2"),
    ("1 2 3\n\n4 5 6\n", "line 2: expected 3 numbers, got 0"),
    (f"1 2 3\n4 5 {SECRET}\n", "line 2: column 3 is not a number"),
    ("1 2 nan\n", "line 1: column 3 is not a finite number"),
    ("1 2 3\n4 inf 6\n", "line 2: column 2 is not a finite number"),
    ("", "has no rows"),
])
def test_read_matrix_rows_reports_line_and_reason_never_the_line(tmp_path, text, match):
    p = _write(tmp_path / "poses.txt", text)
    msg = _refused(safeload.read_matrix_rows, p, 3, field="poses", match=f"{p}: poses: ")
    assert match in msg and SECRET not in msg, msg


def test_read_matrix_rows_limits(tmp_path):
    p = _write(tmp_path / "t.txt", "1\n2\n3\n")
    _refused(safeload.read_matrix_rows, p, 1, max_rows=2, match="more than the limit of 2")
    _refused(safeload.read_matrix_rows, _write(tmp_path / "b.txt", b"1 2\n\xff\n"), 2, match="not UTF-8 text (byte 4)")
    assert safeload.read_matrix_rows(_write(tmp_path / "e.txt", ""), 4, allow_empty=True).shape == (0, 4)


def test_read_array(tmp_path):
    pts = np.arange(8, dtype="<f4").reshape(2, 4)
    p = _write(tmp_path / "000000.bin", pts.tobytes())
    got = safeload.read_array(p, "<f4", 16)
    assert got.shape == (2, 4) and got.flags.writeable and np.array_equal(got, pts)
    labels = safeload.read_array(_write(tmp_path / "000000.label", np.arange(3, dtype="<u4").tobytes()), "<u4")
    assert labels.tolist() == [0, 1, 2]
    _refused(safeload.read_array, _write(tmp_path / "odd.bin", b"\0" * 17), "<f4", 16,
             match="size 17 bytes is not a multiple of the record size (16 bytes)")
    _refused(safeload.read_array, p, "<f4", 16, max_bytes=16, match="file too large")
    bad = pts.copy()
    bad[1, 2] = math.nan
    _refused(safeload.read_array, _write(tmp_path / "nan.bin", bad.tobytes()), "<f4", 16, finite=True,
             match="record 1 is not finite")
    with pytest.raises(ValueError):
        safeload.read_array(p, "<f4", 6)  # a programming error, not a user error


# -- wired into the spec and config loaders ---------------------------------------------------------------------


@pytest.mark.parametrize("line, field", [
    ("adaptive_threshold: .nan", "adaptive_threshold: must be a finite number, got nan"),
    ("adaptive_threshold: .inf", "adaptive_threshold: must be a finite number, got inf"),
    ("adaptive_threshold: 1.0e+999", "adaptive_threshold: must be a finite number, got inf"),
    ("adaptive_threshold: 1e999", 'adaptive_threshold: must be a number in [0, 1], got "1e999"'),  # YAML 1.1: a string
    ("samples: 4", "invalid YAML at line 5 column 1: duplicate key 'samples'"),
])
def test_render_config_numbers_and_duplicates(tmp_path, line, field):
    p = _write(tmp_path / "r.yaml", f"name: r\nresolution: [64, 64]\nsamples: 4\ndenoiser: none\n{line}\n")
    with pytest.raises(SpecError) as e:
        load_render_config(p)
    assert str(e.value) == f"{p}: {field}"


def test_scene_spec_json_and_yaml(tmp_path):
    text = (ROOT / "scenes" / "test_town.json").read_text()
    assert load_spec(_write(tmp_path / "t.json", text)).name == "test_town"
    assert load_spec(_write(tmp_path / "t.yaml", text)).name == "test_town"  # JSON is YAML
    _refused(load_spec, _write(tmp_path / "d.yaml", "name: x\nseed: 1\nseed: 2\n"), match="duplicate key 'seed'")
    _refused(load_spec, _write(tmp_path / "n.json", '{"name": "x", "seed": 1, "paths": {"speed_mps": 1e999}}'),
             match="paths.speed_mps: must be a finite number, got inf")
    _refused(load_spec, _write(tmp_path / "l.yaml", _billion_laughs()))
