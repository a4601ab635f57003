"""Running ``urbangen`` in-process under the hostile-input promise: exit 0, or exit 2 with one line
on stderr, no traceback, nothing written, in bounded time."""

from __future__ import annotations

import time
from pathlib import Path

from generator import cli

#: Seconds one run may take (the slowest valid case builds the test town, ~2 s).
TIME_LIMIT_S = 30.0  # a hang guard (a refusal must not wait on the input), not a speed measurement


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
