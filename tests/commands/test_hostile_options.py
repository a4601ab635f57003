"""Hostile command lines through every command (issue 16): option values and paths.

Hypothesis draws, for every numeric option of every command (found by walking the real
parser, so a new option is covered without touching this file), values no option takes:
NaN, infinities, huge and negative numbers, empty and blank strings, other scripts' digits,
``1_000``, hex, very long and non-printable text; and, for every path argument, paths that
are the wrong kind of thing: a file where a folder belongs and the reverse, a named pipe,
a device, a symlink loop, a path through a file, a missing input, an unwritable folder, an
empty or absurdly long name. ``urbangen`` runs in process and must end with exit 2, exactly
one line on stderr naming the option or the path, no traceback, nothing created, quickly.

Profiles (``tests/conftest.py``): ``CI=1`` runs 25 examples per property, the default 100,
``HYPOTHESIS_PROFILE=thorough`` 1000.
"""

from __future__ import annotations

import argparse
import math
import os
import stat
import tempfile
import time
from pathlib import Path

import pytest

from generator import cli
from generator.commands import options
from generator.safeload import printable
from kits.cli_run import shared_parser
from kits.paths import ROOT

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, assume, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

SPEC = str(ROOT / "scenes" / "test_town.json")
#: Seconds one refused command may take (option errors take milliseconds; a spec load ~0.1 s).
TIME_LIMIT_S = 30.0  # a hang guard (a refusal must not wait on the input), not a speed measurement
IS_ROOT = hasattr(os, "geteuid") and os.geteuid() == 0

# capsys and tmp_path are shared by the examples of one test: every example works in a fresh folder inside it
# (tempfile.mkdtemp, not tmp_path_factory.mktemp: that lists the whole base folder to number each new one, which
# for ~4 000 examples per worker is quadratic, ~20 s)
_cli_settings = settings(suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])

#: A plausible command line per command: ``{ds}`` an existing (empty) folder, ``{out}`` a folder
#: that does not exist, ``{json}`` a file that does not exist. Placeholders are the path slots.
COMMANDS: dict[str, list[str]] = {
    "generate": ["generate", "{spec}", "--config", "{config}", "--out", "{out}"],
    "render": ["render", "{spec}", "--config", "{config}", "--out", "{out}"],
    "validate": ["validate", "{ds}"],
    "preview": ["preview", "{ds}"],
    "stats": ["stats", "{ds}", "--out", "{out}"],
    "layout": ["layout", "{spec}", "--out", "{out}"],
    "lidar": ["lidar", "{spec}", "--out", "{out}"],
    "intensity": ["intensity", "fit", "{ds}", "-o", "{json}"],
    "convert": ["convert", "{ds}", "{out}", "--labels", "unified11"],
    "import_carla": ["import-carla", "{ds}", "{out}", "--sequence", "22"],
    "fuse": ["fuse", "{ds}"],
    "eval": ["eval", "--pred", "{ds}", "--gt", "{ds}", "--json", "{json}"],
    "export": ["export", "cityscapes", "{ds}", "{out}"],
    "openlabel": ["openlabel", "{spec}", "{ds}"],
    "fuse_labels": ["fuse", "{ds}", "--image-labels", "{ds}"],
    "eval_images": ["eval", "--images", "--pred", "{ds}", "--gt", "{ds}", "--json", "{json}"],
    "gap": ["gap", "{ds}", "{ds}", "--out", "{out}"],
}
#: What each path slot must be: an existing input (file or folder) or an output (folder or file).
ROLES = {"spec": "in_file", "config": "in_file", "ds": "in_dir", "out": "out_dir", "json": "out_file"}


def _parser_of(name: str) -> argparse.ArgumentParser:
    sub = next(a for a in cli.build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    p = sub.choices[COMMANDS[name][0]]
    if name == "intensity":
        p = next(a for a in p._actions if isinstance(a, argparse._SubParsersAction)).choices["fit"]
    return p


def _options(kinds: set[str]) -> list[tuple[str, str, argparse.Action]]:
    """(command, option string, action) of every option whose parser helper parses one of ``kinds``."""
    out = []
    for name in COMMANDS:
        for action in _parser_of(name)._actions:
            if action.option_strings and getattr(action.type, "kind", None) in kinds:
                out.append((name, max(action.option_strings, key=len), action))
    return out


NUMERIC = _options({"integer", "number", "integer list", "sequence", "sequence list"})


def test_every_numeric_option_is_parsed_strictly():
    """No option of any command is parsed with plain int() or float() (they take nan, inf, 1_0, '\u0661')."""
    loose = [(name, a.option_strings) for name in COMMANDS for a in _parser_of(name)._actions
             if a.type in (int, float)]
    assert not loose, loose
    assert len(NUMERIC) >= 25, [(n, o) for n, o, _ in NUMERIC]
    covered = {(n, o) for n, o, _ in NUMERIC}
    for must in [("generate", "--frames"), ("generate", "--workers"), ("render", "--first"), ("fuse", "--voxel"),
                 ("lidar", "--dropout"), ("lidar", "--jitter-m"), ("lidar", "--gap-intensity"),
                 ("lidar", "--constant-intensity"), ("eval", "--min-points"), ("openlabel", "--min-points"),
                 ("import_carla", "--sequence"), ("import_carla", "--seed"), ("preview", "--frames")]:
        assert must in covered, must


# -- hostile values --------------------------------------------------------------------------------------------

_WORDS = ["nan", "NaN", "-nan", "inf", "-inf", "+inf", "Infinity", "infinity", "1e309", "-1e309", "1e999999",
          "", " ", "\t", "1 ", " 1", "0x10", "0b1", "0o7", "1_000", "1e", "e5", ".", "-", "+", "--", "1.2.3", "1,5",
          "\u0661", "\u00b2", "\uff11", "\u0967", "\u2167", "1\u00a0", "\U0001d7d9", "\n", "1\n2", "\x1b[31m",
          "\udcff", "0" * 5000, "9" * 400, "1" + "0" * 40, "-" + "9" * 30, "1e-400", "none", "None", "null",
          "true", "[1]", "{}", "'1'", "1/2", "½", "1e+", "+-1", "--frames", "-1e5", "-.5"]


def _numbers_outside(lo, hi):
    """Decimal text of numbers just and far outside [lo, hi]."""
    parts = []
    if lo is not None:
        parts += [st.integers(max_value=math.floor(lo) - 1).map(str),
                  st.floats(max_value=float(lo), exclude_max=True, allow_nan=False).map(repr)]
    if hi is not None:
        parts += [st.integers(min_value=math.ceil(hi) + 1).map(str),
                  st.floats(min_value=float(hi), exclude_min=True, allow_nan=False).map(repr)]
    return st.one_of(*parts) if parts else st.nothing()


@st.composite
def hostile_value(draw, action: argparse.Action) -> str:
    t = action.type
    lo, hi = getattr(t, "lo", None), getattr(t, "hi", None)
    text = draw(st.one_of(
        st.sampled_from(_WORDS),
        _numbers_outside(lo, hi),
        st.floats(allow_nan=True, allow_infinity=True).map(repr),
        st.integers(min_value=10**19, max_value=10**400).map(str),
        st.text(max_size=12),
        # every character UTF-8 encodes (all but the surrogates); said as a category, not codec="utf-8", which
        # makes hypothesis encode all 1.1 million code points once per process (~2-4 s) to find the same set
        st.text(alphabet=st.characters(exclude_categories=["Cs"]), min_size=2000, max_size=6000),
    ))
    try:  # keep only what the option refuses (a valid value would start a real run)
        t(text)
    except argparse.ArgumentTypeError:
        return text
    assume(False)


@pytest.fixture(autouse=True)
def _one_parser(monkeypatch):
    """The examples share one parser (:func:`kits.cli_run.shared_parser`)."""
    monkeypatch.setattr(cli, "build_parser", shared_parser)


def _listing(folder: Path) -> set[str]:
    return {str(p.relative_to(folder)) for p in folder.rglob("*")}


def run_refused(capsys, argv: list[str], work: Path) -> str:
    """Run ``urbangen argv``: exit 2, one line, no traceback, nothing new under ``work``, quickly."""
    before = _listing(work)
    capsys.readouterr()
    t0 = time.perf_counter()
    rc = cli.main(argv)
    elapsed = time.perf_counter() - t0
    _, err = capsys.readouterr()
    assert "Traceback" not in err, err
    assert rc == 2, (rc, argv[:8], err)
    assert err.endswith("\n") and err.count("\n") == 1, err
    assert len(err) <= cli.MAX_MESSAGE_CHARS + 200, len(err)
    assert elapsed < TIME_LIMIT_S, f"{argv[:3]} took {elapsed:.1f} s"
    assert _listing(work) == before, f"created: {_listing(work) - before}"
    return err


def _argv(name: str, work: Path, **slots) -> list[str]:
    values = {"spec": SPEC, "config": "test", "ds": str(work / "ds"), "out": str(work / "out"),
              "json": str(work / "result.json"), **slots}
    return [values[a[1:-1]] if a.startswith("{") else a for a in COMMANDS[name]]


def _workdir(tmp_path: Path) -> Path:
    work = Path(tempfile.mkdtemp(prefix="hostile-cli", dir=tmp_path))
    (work / "ds").mkdir()
    return work


@pytest.mark.parametrize("name, flag, action", NUMERIC, ids=[f"{n}{o}" for n, o, _ in NUMERIC])
@_cli_settings
@given(data=st.data(), form=st.sampled_from(["separate", "equals"]))
def test_hostile_numeric_options(capsys, tmp_path, name, flag, action, data, form):
    value = data.draw(hostile_value(action), label="value")
    work = _workdir(tmp_path)
    opt = [f"{flag}={value}"] if form == "equals" else [flag, value]
    err = run_refused(capsys, ["-q", *_argv(name, work), *opt], work)
    prog = "urbangen intensity fit" if name == "intensity" else f"urbangen {COMMANDS[name][0]}"
    # "--frames 0" names the option; "--frames -inf" is read as an option itself: argparse names --frames too
    assert err.startswith(f"{prog}: {flag}: "), err


# -- hostile paths ---------------------------------------------------------------------------------------------

#: Path kinds refused for every role (made inside the example's folder; see :func:`_make`).
ALWAYS_BAD = ["fifo", "loop", "through_file", "empty", "long", "long_name", "dangling", "not_utf8"]
BAD_FOR = {
    "in_file": ALWAYS_BAD + ["missing", "folder", "device"],
    "in_dir": ALWAYS_BAD + ["missing", "file", "device", "empty_folder"],
    "out_dir": ALWAYS_BAD + ["file", "device", "unwritable"],
    "out_file": ALWAYS_BAD + ["folder", "device", "unwritable"],
}


def _make(kind: str, work: Path) -> str | None:
    """A path of ``kind`` (None when this machine cannot make it)."""
    junk = work / "junk"
    junk.mkdir(exist_ok=True)
    if kind == "fifo":
        if not hasattr(os, "mkfifo"):
            return None
        p = junk / "fifo"
        if not p.exists():
            os.mkfifo(p)
        return str(p)
    if kind == "device":
        p = junk / "null"
        if not p.exists():
            try:
                os.mknod(p, 0o666 | stat.S_IFCHR, os.makedev(1, 3))  # /dev/null's numbers
            except (OSError, AttributeError):
                return None
        return str(p)
    if kind == "loop":
        p = junk / "loop"
        if not os.path.lexists(p):
            p.symlink_to(p)
        return str(p)
    if kind == "dangling":
        p = junk / "dangling"
        if not os.path.lexists(p):
            p.symlink_to(junk / "nowhere" / "x")
        return str(p)
    if kind in ("file", "through_file"):
        p = junk / "file"
        p.write_text("not what you think\n")
        return str(p if kind == "file" else p / "below")
    if kind in ("folder", "empty_folder"):
        (junk / "folder").mkdir(exist_ok=True)
        return str(junk / "folder")
    if kind == "missing":
        return str(junk / "missing" / "thing.json")
    if kind == "unwritable":
        if IS_ROOT:  # root writes anywhere; the unit tests simulate EACCES instead
            return None
        ro = junk / "ro"
        ro.mkdir(exist_ok=True)
        ro.chmod(0o555)
        return str(ro / "out")
    if kind == "empty":
        return ""
    if kind == "long":
        return str(junk) + "/" + ("d" * 200 + "/") * 30 + "x"  # 6000 characters
    if kind == "not_utf8":  # what Python makes of a file name with bytes that are not UTF-8
        p = os.fsencode(junk) + b"/caf\xe9"
        os.mkdir(p)
        return os.fsdecode(p)
    if kind == "long_name":
        return str(junk / ("n" * 300))
    raise AssertionError(kind)


SLOTS = [(name, slot[1:-1]) for name, argv in COMMANDS.items() for slot in argv if slot.startswith("{")]


@pytest.mark.parametrize("name, slot", sorted(set(SLOTS)), ids=[f"{n}-{s}" for n, s in sorted(set(SLOTS))])
@_cli_settings
@given(data=st.data())
def test_hostile_paths(capsys, tmp_path, name, slot, data):
    role = ROLES[slot]
    kind = data.draw(st.sampled_from(BAD_FOR[role]), label="kind")
    work = _workdir(tmp_path)
    bad = _make(kind, work)
    assume(bad is not None)
    err = run_refused(capsys, _argv(name, work, **{slot: bad}), work)  # no -q: not even a warning line
    prog = "urbangen intensity fit" if name == "intensity" else f"urbangen {COMMANDS[name][0]}"
    assert err.startswith(prog), err
    if kind not in ("empty", "long"):  # those two are named by their option: the path itself is not shown
        assert printable(bad, 40)[:30] in err, err


# -- the parsers themselves ------------------------------------------------------------------------------------


@given(text=st.one_of(st.text(max_size=40), st.sampled_from(_WORDS), st.integers().map(str),
                      st.floats().map(repr)), bounds=st.sampled_from([(0, 10), (1, 100_000), (-5, 5), (0, None)]))
def test_integer_accepts_exactly_plain_decimal_integers_in_range(text, bounds):
    lo, hi = bounds
    try:
        value = options.Integer(lo, hi)(text)
    except argparse.ArgumentTypeError as e:
        assert "\n" not in str(e) and len(str(e)) < 200
        return
    assert text.isascii() and text.lstrip("+-").isdigit() and text == text.strip()
    assert value == int(text) and lo <= value and (hi is None or value <= hi)


@given(text=st.one_of(st.text(max_size=40), st.sampled_from(_WORDS), st.floats().map(repr),
                      st.integers().map(str)), bounds=st.sampled_from([(0.0, 1.0), (0.05, 50.0), (0.5, 20.0)]))
def test_number_accepts_exactly_finite_decimals_in_range(text, bounds):
    lo, hi = bounds
    try:
        value = options.Number(lo, hi)(text)
    except argparse.ArgumentTypeError as e:
        assert "\n" not in str(e) and len(str(e)) < 200
        return
    assert text.isascii() and "_" not in text and text == text.strip() and text.lower() not in ("nan", "inf")
    assert math.isfinite(value) and lo <= value <= hi and value == float(text)


# -- whole command lines -----------------------------------------------------------------------------------------

_FLAGS = sorted({o for n in COMMANDS for a in _parser_of(n)._actions for o in a.option_strings})
_TOKENS = st.one_of(
    st.sampled_from(_FLAGS),
    st.sampled_from(_WORDS),
    st.sampled_from([c[0] for c in COMMANDS.values()]),
    st.sampled_from([".", "..", "-", "fit", "cityscapes", "all", "day:fog", "-q", "-v", "-vv"]),
    st.text(max_size=8),
)


@_cli_settings
@given(command=st.sampled_from(sorted({c[0] for c in COMMANDS.values()})), tokens=st.lists(_TOKENS, max_size=8))
def test_random_command_lines(capsys, tmp_path, monkeypatch, command, tokens):
    """Any mix of real flags and junk, run in an empty folder: --help/--version (exit 0) or one line, exit 2."""
    work = Path(tempfile.mkdtemp(prefix="hostile-argv", dir=tmp_path))
    monkeypatch.chdir(work)  # '.' and relative names point into an empty folder: nothing valid to run on
    argv = [command, *tokens]
    capsys.readouterr()
    rc = cli.main(argv)
    out, err = capsys.readouterr()
    assert "Traceback" not in err, err
    if rc == 0:
        assert {"-h", "--help", "--version"} & set(argv) or "help" in out.lower(), (argv, out[:200])
    else:
        assert rc == 2 and err.count("\n") == 1, (rc, argv, err)
    assert list(work.iterdir()) == [], (argv, list(work.iterdir()))
