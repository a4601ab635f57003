"""Where the test suite spends its time: wall clock and test time per folder, serial beside parallel.

Runs pytest twice in this checkout -- the baseline (serial) and the candidate (by default
``-n 2 --dist loadgroup``, two pytest-xdist workers) -- each writing a JUnit XML report into
``OUT``, then prints side by side: the wall time of each run, the summed test time (setup + call +
teardown) per test folder, and the slowest tests. Both runs see the same machine, so the ratio of
the two is meaningful even when the machine is busy; the absolute times are not.

Usage::

    python bench/test_time.py OUT [--candidate "-n 2 --dist loadgroup"] [--baseline ""]
                              [--no-baseline] [--slowest 25] [-- PYTEST_ARGS...]

``PYTEST_ARGS`` select tests (default: the whole suite), e.g. ``-- tests/layout -m "not blender"``.
A failing test does not stop the bench (its time still counts); the exit code is pytest's.
"""

from __future__ import annotations

import argparse
import shlex
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
from collections import defaultdict
from pathlib import Path


def run(label: str, extra: list[str], select: list[str], out: Path) -> tuple[float, int, Path]:
    """Run pytest with ``extra`` options on ``select``; returns (wall seconds, exit code, report)."""
    report = out / f"{label}.xml"
    cmd = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", f"--junitxml={report}", *extra, *select]
    print(f"[{label}] {shlex.join(cmd)}", flush=True)
    t0 = time.perf_counter()
    rc = subprocess.call(cmd, stdout=subprocess.DEVNULL)
    return time.perf_counter() - t0, rc, report


def per_test(report: Path) -> dict[str, float]:
    """Test id -> seconds (setup + call + teardown) from a JUnit XML report."""
    out = {}
    for case in ET.parse(report).getroot().iter("testcase"):
        out[f"{case.get('classname')}::{case.get('name')}"] = float(case.get("time") or 0.0)
    return out


def folder(test_id: str) -> str:
    """``tests.layout.network.test_one_way::x`` -> ``tests/layout`` (the package's folder)."""
    parts = test_id.split("::")[0].split(".")
    return "/".join(parts[:2]) if len(parts) > 2 else "tests (top level)"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out", type=Path, help="folder for the JUnit reports")
    ap.add_argument("--baseline", default="", help="pytest options of the baseline run (default: serial)")
    ap.add_argument("--candidate", default="-n 2 --dist loadgroup", help="pytest options of the candidate run")
    ap.add_argument("--no-baseline", action="store_true", help="run the candidate only")
    ap.add_argument("--slowest", type=int, default=25, help="how many of the slowest tests to list")
    argv = sys.argv[1:] if argv is None else list(argv)
    # the selection is everything after "--" (argparse would take the first positional run for it, so
    # ``OUT --no-baseline -- tests/x`` was refused): split it off before parsing
    cut = argv.index("--") if "--" in argv else len(argv)
    args = ap.parse_args(argv[:cut])
    args.select = argv[cut + 1:]
    args.out.mkdir(parents=True, exist_ok=True)

    runs = []
    if not args.no_baseline:
        runs.append(("baseline", shlex.split(args.baseline)))
    runs.append(("candidate", shlex.split(args.candidate)))
    results = {}
    rc_all = 0
    for label, extra in runs:
        wall, rc, report = run(label, extra, args.select, args.out)
        rc_all = rc_all or rc
        results[label] = (wall, per_test(report) if report.is_file() else {})

    labels = [label for label, _ in runs]
    print()
    print(f"{'':32s}" + "".join(f"{label:>14s}" for label in labels))
    print(f"{'wall clock (s)':32s}" + "".join(f"{results[label][0]:14.1f}" for label in labels))
    print(f"{'tests':32s}" + "".join(f"{len(results[label][1]):14d}" for label in labels))
    print(f"{'summed test time (s)':32s}" + "".join(f"{sum(results[label][1].values()):14.1f}" for label in labels))
    sums: dict[str, dict[str, float]] = defaultdict(lambda: defaultdict(float))
    for label in labels:
        for test_id, s in results[label][1].items():
            sums[folder(test_id)][label] += s
    print("\nsummed test time per folder (s)")
    for name in sorted(sums, key=lambda f: -max(sums[f].values())):
        print(f"  {name:30s}" + "".join(f"{sums[name][label]:14.1f}" for label in labels))
    last = results[labels[-1]][1]
    print(f"\nslowest {args.slowest} tests of the {labels[-1]} run (s)")
    for test_id, s in sorted(last.items(), key=lambda kv: -kv[1])[:args.slowest]:
        print(f"  {s:8.1f}  {test_id}")
    return rc_all


if __name__ == "__main__":
    sys.exit(main())
