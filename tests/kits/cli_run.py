"""Running ``urbangen`` in-process under the hostile-input promise: exit 0, or exit 2 with one line
on stderr, no traceback, nothing written, in bounded time."""

from __future__ import annotations

import argparse
import functools
import time
from pathlib import Path

from generator import cli

_build_parser = cli.build_parser  # the real one (tests put shared_parser in its place)

#: Seconds one run may take (the slowest valid case builds the test town, ~2 s).
TIME_LIMIT_S = 30.0  # a hang guard (a refusal must not wait on the input), not a speed measurement


@functools.cache
def shared_parser() -> argparse.ArgumentParser:
    """``cli.build_parser()`` made once per process: it makes the same parser every time and parsing leaves it as
    it was, so tests that run thousands of command lines (``monkeypatch.setattr(cli, "build_parser",
    shared_parser)``) run ``cli.main`` as a fresh process would, without rebuilding ~700 options (~20 ms) each."""
    return _build_parser()


def _listing(folder: Path) -> set[str]:
    return {str(p.relative_to(folder)) for p in folder.rglob("*")}


def run_cli(capsys, argv: list[str], workdir: Path, out: Path) -> tuple[int, str]:
    """Run ``urbangen argv``; check the hostile-input promise; return (exit code, stderr)."""
    before = _listing(workdir)
    capsys.readouterr()
    t0 = time.perf_counter()
    try:
        rc = cli.main(argv)
    except SystemExit as e:  # argparse
        rc = e.code
    elapsed = time.perf_counter() - t0
    _, err = capsys.readouterr()
    assert elapsed < TIME_LIMIT_S, f"took {elapsed:.1f} s"
    assert "Traceback" not in err, err
    if rc == 0:
        return rc, err
    assert rc == 2, (rc, err)
    assert err.endswith("\n") and err.count("\n") == 1, err
    assert not out.exists(), f"{out} was created: {_listing(out)}"
    assert _listing(workdir) == before, "files appeared beside the input"
    return rc, err
