"""Hostile scene specs, render configs and sensor files through the real command line (issue 16).

Hypothesis mutates the shipped test town, the ``test`` render config and the VLP-16 sensor
table (wrong types, NaN/inf, huge numbers, deep nesting, duplicate keys, YAML alias bombs,
random JSON/YAML trees, paths leading out of the spec's folder) and runs ``urbangen`` in
process. Whatever the input, the command must end with exit 2 (or 0 when the mutation
happens to be valid), exactly one line on stderr naming the file, no traceback, nothing
written, within a few seconds.

Commands that would start real work on a valid input get an output folder that is an
existing file (``--out taken``), which is checked AFTER the files are loaded (options are
checked when parsed, before any file): every file is still read and validated first, and
the run stays bounded however the mutation turned out. One property runs ``layout``
unmodified and accepts a valid result.

Profiles (see ``conftest.py``): ``CI=1`` runs 25 examples per property, the default 100,
``HYPOTHESIS_PROFILE=thorough`` 1000.
"""

from __future__ import annotations

import copy
import json
import os
import tempfile
import time
from pathlib import Path

import pytest
import yaml

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from generator.spec import load_spec  # noqa: E402
from kits.cli_run import TIME_LIMIT_S, run_cli  # noqa: E402
from kits.hostile_values import HOSTILE  # noqa: E402
from kits.json_kit import value_paths  # noqa: E402
from kits.paths import ROOT  # noqa: E402

BASE_SPEC = load_spec(ROOT / "scenes" / "test_town.json").to_dict()  # every field, defaults filled in
BASE_CONFIG = yaml.safe_load((ROOT / "render_configs" / "test.yaml").read_text())
BASE_SENSOR = yaml.safe_load((ROOT / "generator" / "lidar" / "sensors" / "vlp16.yaml").read_text())
SECRET = "hunter2-TOP-SECRET-token"

# capsys is function-scoped; reading it after every example resets it, so sharing it is safe.
_cli_settings = settings(suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])


# -- building documents ------------------------------------------------------------------------------------------

SPEC_PATHS = value_paths(BASE_SPEC)
CONFIG_PATHS = value_paths(BASE_CONFIG)
SENSOR_PATHS = value_paths(BASE_SENSOR)


def _deep(n: int, fmt: str) -> str:
    return "[" * n + "]" * n if n % 2 else ('{"a": ' if fmt == "json" else "{a: ") * n + "1" + "}" * n


def _laughs(levels: int = 8) -> str:
    parts = ["&l0 [lol, lol, lol, lol, lol, lol, lol, lol, lol, lol]"]
    parts += [f"&l{i} [" + ", ".join([f"*l{i - 1}"] * 10) + "]" for i in range(1, levels + 1)]
    return "[" + ", ".join(parts) + "]"


#: Text spliced in where a Python value cannot say it: bad literals, bombs, duplicate keys.
RAW = {
    "json": st.one_of(
        st.sampled_from(["NaN", "Infinity", "-Infinity", "1e999", "-1e400", "9" * 400, "9" * 5000,
                         '{"a": 1, "a": 2}', '"\\ud800"', '{"\\udfff": 1}', "tru", "[1,]", "0x10", "'single'"]),
        st.integers(65, 3000).map(lambda n: _deep(n, "json")),
        st.just(_deep(100_001, "json")),
    ),
    "yaml": st.one_of(
        st.sampled_from([".nan", ".inf", "-.inf", "1.0e+999", "9" * 5000, "{a: 1, a: 2}", "&r [*r]", "*nowhere",
                         "!!python/object/apply:os.system [echo]", "!!set {a, b}", "!!binary aGk=", "2020-01-01",
                         "{1: a}", "[a, b", "'unterminated", "\"\\q\"", "@reserved", "|\n  block", "- a\n- b",
                         _laughs(), "{? [a]: 1}", "!!timestamp 2001-12-14", "{<<: [1]}"]),
        st.integers(65, 3000).map(lambda n: _deep(n, "yaml")),
        st.just(_deep(100_001, "yaml")),
    ),
}

_scalars = st.one_of(
    st.none(), st.booleans(), st.integers(), st.floats(),  # floats include nan and +-inf
    st.integers(min_value=10**300, max_value=10**330), st.text(max_size=30),
)
#: Random JSON-like trees (YAML gets the same trees).
TREES = st.recursive(_scalars, lambda c: st.lists(c, max_size=4) | st.dictionaries(st.text(max_size=12), c, max_size=4),
                     max_leaves=16)


class Doc:
    """A document under mutation plus the raw text spliced in at placeholders."""

    def __init__(self, base):
        self.data = copy.deepcopy(base)
        self.raw: dict[str, str] = {}

    def placeholder(self, text: str) -> str:
        key = f"RAWTOKEN{len(self.raw)}X"
        self.raw[key] = text
        return key

    def set(self, path: tuple, value) -> None:
        if not path:
            self.data = value
            return
        node = self.data
        for k in path[:-1]:
            if isinstance(node, dict) and k in node or isinstance(node, list) and isinstance(k, int) and k < len(node):
                node = node[k]
            else:
                return  # an earlier mutation changed the shape here
        if isinstance(node, dict) or isinstance(node, list) and isinstance(path[-1], int) and path[-1] < len(node):
            node[path[-1]] = value

    def delete(self, path: tuple) -> None:
        parent, key = path[:-1], path[-1]
        node = self.data
        for k in parent:
            try:
                node = node[k]
            except (KeyError, IndexError, TypeError):
                return
        if isinstance(node, dict):
            node.pop(key, None)

    def text(self, fmt: str) -> str:
        if fmt == "json":
            out = json.dumps(self.data)  # NaN/Infinity come out as bare literals: invalid JSON on purpose
            for key, raw in self.raw.items():
                out = out.replace(f'"{key}"', raw)
        else:
            out = yaml.safe_dump(self.data, sort_keys=False, width=1 << 30)
            for key, raw in self.raw.items():
                out = out.replace(key, raw)
        return out


ALL_OPS = ("value", "value", "value", "raw", "raw", "delete", "new_key", "root")


@st.composite
def mutated(draw, base, paths, fmt: str, values=TREES, max_mutations: int = 3, ops=ALL_OPS) -> str:
    """Text of ``base`` after 1..max_mutations random mutations, in ``fmt`` (json or yaml)."""
    doc = Doc(base)
    for _ in range(draw(st.integers(1, max_mutations))):
        path = draw(st.sampled_from(paths))
        op = draw(st.sampled_from(ops))
        if op == "value":
            doc.set(path, draw(values))
        elif op == "raw":
            doc.set(path, doc.placeholder(draw(RAW[fmt])))
        elif op == "delete":
            doc.delete(path)
        elif op == "new_key":
            doc.set(path[:-1] + (draw(st.text(min_size=1, max_size=12)),), draw(values))
        else:
            doc.set((), draw(st.one_of(values, RAW[fmt].map(doc.placeholder))))
    return doc.text(fmt)


# -- running the command line ------------------------------------------------------------------------------------


def _taken(work: Path) -> Path:
    """An existing file given as ``--out``: refused after the spec, config and sensor files are read."""
    taken = work / "taken"
    taken.write_text("")
    return taken


# -- properties --------------------------------------------------------------------------------------------------


@_cli_settings
@given(fmt=st.sampled_from(["json", "yaml"]), data=st.data())
def test_layout_on_a_hostile_spec(capsys, fmt, data):
    """``urbangen layout SPEC --out DIR``, unmodified: exit 2 with one line naming the spec, or a valid run.

    No deletions here: a deleted section falls back to the (much larger) default town, and
    building that is slow, not wrong. HOSTILE values never make an in-range number either.
    """
    text = data.draw(mutated(BASE_SPEC, SPEC_PATHS, fmt, HOSTILE, ops=("value", "raw", "new_key")))
    with tempfile.TemporaryDirectory(prefix="hostile-") as tmp:
        work = Path(tmp)
        spec = work / f"spec.{fmt}"
        spec.write_text(text, encoding="utf-8")
        out = work / "out"
        rc, err = run_cli(capsys, ["-q", "layout", str(spec), "--out", str(out)], work, out)
        if rc == 0:
            assert (out / f"{BASE_SPEC['name']}_summary.json").is_file() or any(out.glob("*_summary.json"))
        else:
            assert err.startswith(f"urbangen layout: {spec}: "), err


@_cli_settings
@given(fmt=st.sampled_from(["json", "yaml"]), data=st.data())
def test_any_tree_as_a_spec(capsys, fmt, data):
    """Random trees and raw splices anywhere in a spec; ``lidar`` reads spec, sensor and config first."""
    text = data.draw(mutated(BASE_SPEC, SPEC_PATHS, fmt, TREES))
    with tempfile.TemporaryDirectory(prefix="hostile-") as tmp:
        work = Path(tmp)
        spec = work / f"spec.{fmt}"
        spec.write_text(text, encoding="utf-8")
        out = work / "out"
        argv = ["-q", "lidar", str(spec), "--out", str(_taken(work)), "--frames", "1"]
        rc, err = run_cli(capsys, argv, work, out)
        assert rc == 2
        named = (f"urbangen lidar: {spec}: ", "urbangen lidar: --out: ",
                 f"urbangen lidar: {work}/")  # the last: a sensor file the (valid) spec names
        assert err.startswith(named) or "intensity profile" in err, err


@_cli_settings
@given(data=st.data())
def test_any_render_config(capsys, root, data):
    """Hostile render configs through ``urbangen render``: the config is loaded before any work."""
    text = data.draw(mutated(BASE_CONFIG, CONFIG_PATHS, "yaml", st.one_of(TREES, HOSTILE)))
    with tempfile.TemporaryDirectory(prefix="hostile-") as tmp:
        work = Path(tmp)
        cfg = work / "config.yaml"
        cfg.write_text(text, encoding="utf-8")
        out = work / "out"
        argv = ["-q", "render", str(root / "scenes" / "test_town.json"), "--config", str(cfg), "--out",
                str(_taken(work)), "--frames", "1"]
        rc, err = run_cli(capsys, argv, work, out)
        assert rc == 2
        assert err.startswith((f"urbangen render: {cfg}: ", "urbangen render: --out: ")), err


def _sensor_text(data) -> str:
    text = data.draw(mutated(BASE_SENSOR, SENSOR_PATHS, "yaml", st.one_of(TREES, HOSTILE), max_mutations=2))
    if data.draw(st.booleans()):  # a secret-looking line somewhere: a parse error that must not quote it
        lines = text.splitlines()
        lines.insert(data.draw(st.integers(0, len(lines))), f"password={SECRET}")
        text = "\n".join(lines) + "\n"
    return text


@_cli_settings
@given(data=st.data(), where=st.sampled_from(["sensor.yaml", "sub/../sensor.yaml", "../outside.yaml",
                                              "ABS", "link_out.yaml", "linkdir/outside.yaml", "loop.yaml",
                                              "fifo.yaml", "sub", "missing.yaml", "sensor.yaml\n", "a\u0000b"]))
def test_sensor_file_in_a_spec(capsys, data, where):
    """``sensors.lidar.sensor_file``: confined to the spec's folder; a bad table is one line; secrets stay put."""
    with tempfile.TemporaryDirectory(prefix="hostile-") as tmp:
        work = Path(tmp)
        outside = work / "outside.yaml"
        outside.write_text(f"name: {SECRET}\n{SECRET}: [\n")  # outside the spec's folder: never read
        specs = work / "specs"
        (specs / "sub").mkdir(parents=True)
        (specs / "sensor.yaml").write_text(_sensor_text(data), encoding="utf-8")
        (specs / "link_out.yaml").symlink_to(outside)
        (specs / "linkdir").symlink_to(work)
        (specs / "loop.yaml").symlink_to(specs / "loop.yaml")
        if hasattr(os, "mkfifo"):
            os.mkfifo(specs / "fifo.yaml")
        sensor_file = str(outside) if where == "ABS" else where
        doc = {"name": "t", "seed": 1, "town": {"blocks_x": 1, "blocks_y": 1},
               "sensors": {"lidar": {"sensor_file": sensor_file}}}
        spec = specs / "spec.json"
        spec.write_text(json.dumps(doc))
        out = work / "out"
        argv = ["-q", "lidar", str(spec), "--out", str(_taken(work)), "--frames", "1"]
        rc, err = run_cli(capsys, argv, work, out)
        assert rc == 2
        assert SECRET not in err and "hunter2" not in err, err
        if where in ("../outside.yaml", "ABS", "link_out.yaml", "linkdir/outside.yaml", "a\u0000b"):
            assert err.startswith(f"urbangen lidar: {spec}: sensors.lidar.sensor_file: "), err
        else:
            assert err.startswith((f"urbangen lidar: {specs}", "urbangen lidar: --out: ")), err


# -- fixed cases the properties might miss -------------------------------------------------------------------------


@pytest.mark.parametrize("text, reason", [
    ("[" * 100_000 + "]" * 100_000, "invalid JSON: nested deeper than 64 levels"),
    ('{"name": "x", "seed": 1, "seed": 2}', "invalid JSON: duplicate key 'seed'"),
    ('{"name": "x", "seed": 1, "paths": {"speed_mps": 1e999}}', "paths.speed_mps: must be a finite number, got inf"),
    ('{"name": "x", "seed": 1, "town\\n\\u0000": 1}', "town\\n\\x00: unknown key (allowed here:"),
    ('{"name": "x", "seed": 1, "\\ud800": 1}', "\\ud800: unknown key"),
    ('{"name": "x", "seed": 1, "streets": {"intersection_angle_deg": [50, 80]}}',
     "streets.intersection_angle_deg: must lie within [60, 90] degrees, got [50, 80]"),
    ('{"name": "x", "seed": 1, "streets": {"intersection_angle_deg": [80, 70]}}',
     "streets.intersection_angle_deg: must be a range [low, high] with low <= high"),
    ('{"name": "x", "seed": 1, "streets": {"intersection_angle_deg": [70, 1e999]}}',
     "streets.intersection_angle_deg[1]: must be a finite number, got inf"),
    ('{"name": "x", "seed": 1, "streets": {"intersection_angle_deg": "70"}}',
     "streets.intersection_angle_deg: must be a list of 2 items, each a number"),
])
def test_layout_fixed_hostile_specs(tmp_path, capsys, text, reason):
    spec = tmp_path / "spec.json"
    spec.write_text(text)
    out = tmp_path / "out"
    rc, err = run_cli(capsys, ["layout", str(spec), "--out", str(out)], tmp_path, out)
    assert rc == 2 and err.startswith(f"urbangen layout: {spec}: {reason}"), err


def test_yaml_bomb_spec_fails_fast(tmp_path, capsys):
    spec = tmp_path / "lol.yaml"
    spec.write_text("name: x\nseed: 1\nlol: " + _laughs(9) + "\n")
    out = tmp_path / "out"
    t0 = time.perf_counter()
    rc, err = run_cli(capsys, ["layout", str(spec), "--out", str(out)], tmp_path, out)
    assert rc == 2 and time.perf_counter() - t0 < TIME_LIMIT_S and "aliases" in err, err


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_fifo_and_device_as_spec_and_config(tmp_path, capsys, root):
    fifo = tmp_path / "spec.json"
    os.mkfifo(fifo)
    out = tmp_path / "out"
    rc, err = run_cli(capsys, ["layout", str(fifo), "--out", str(out)], tmp_path, out)
    assert rc == 2 and "named pipe" in err
    if os.path.exists("/dev/zero"):
        argv = ["render", str(root / "scenes" / "test_town.json"), "--config", "/dev/zero", "--out", str(out)]
        rc, err = run_cli(capsys, argv, tmp_path, out)
        assert rc == 2 and err == "urbangen render: /dev/zero: is a character device, expected a regular file\n"


def test_render_config_nan_names_the_field(tmp_path, capsys, root):
    cfg = tmp_path / "nan.yaml"
    cfg.write_text("name: nan\nresolution: [64, 64]\nsamples: 2\nadaptive_threshold: .nan\n")
    out = tmp_path / "out"
    argv = ["render", str(root / "scenes" / "test_town.json"), "--config", str(cfg), "--out", str(out)]
    rc, err = run_cli(capsys, argv, tmp_path, out)
    assert rc == 2 and err == f"urbangen render: {cfg}: adaptive_threshold: must be a finite number, got nan\n"


def test_bad_sensor_file_never_prints_its_content(tmp_path, capsys):
    (tmp_path / "sensor.yaml").write_text(f"name: s\nrotation_hz: 10\n{SECRET}\nazimuth_steps: 10\n")
    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps({"name": "t", "seed": 1, "sensors": {"lidar": {"sensor_file": "sensor.yaml"}}}))
    out = tmp_path / "out"
    rc, err = run_cli(capsys, ["lidar", str(spec), "--out", str(out)], tmp_path, out)
    sensor = tmp_path / "sensor.yaml"
    assert rc == 2 and err.startswith(f"urbangen lidar: {sensor}: invalid YAML at line 4 column 1: "), err
    assert SECRET not in err


@pytest.mark.parametrize("sensor_file", ["../secret.yaml", "/etc/passwd", "up/secret.yaml"])
def test_sensor_file_outside_the_spec_folder(tmp_path, capsys, sensor_file):
    (tmp_path / "secret.yaml").write_text(f"{SECRET}\n")
    specs = tmp_path / "specs"
    specs.mkdir()
    (specs / "up").symlink_to(tmp_path)
    spec = specs / "spec.json"
    spec.write_text(json.dumps({"name": "t", "seed": 1, "sensors": {"lidar": {"sensor_file": sensor_file}}}))
    out = tmp_path / "out"
    rc, err = run_cli(capsys, ["lidar", str(spec), "--out", str(out)], tmp_path, out)
    assert rc == 2 and err.startswith(f"urbangen lidar: {spec}: sensors.lidar.sensor_file: "), err
    assert SECRET not in err
