"""The README's main job, timed, for this tree and a baseline tree side by side; same bytes or not.

Runs ``generate scenes/first_look.json --config first_look --frames 2 --variants
day:clear,day:rain_fog,night:wet --workers 2`` (the README's command) once per tree, each into its own folder
under ``OUT``, with ``PYTHONPATH`` set to the tree, and prints per tree: wall time, CPU time (user +
sys of the job and every process it started), the time of each progress item, the manifest's
figures (town products, worker set-up, seconds in Cycles); then the ratios of this tree against the
baseline and the byte-identity check: the SHA-256 of every file of both datasets (``manifest.json``,
which records times and the run, and the journal excepted; an image's JSON is hashed without its
``timings_s``, seconds measured in the run). Both jobs write to the same folder, ``OUT/dataset``
(statistics name the folder they read), which is then renamed ``OUT/baseline`` or ``OUT/tree``.

Usage::

    python bench/main_job.py OUT [--baseline TREE] [--tree TREE] [--workers N]

Take both CPU slots for a timing run; say what else was running (``uptime`` is printed).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import logging
import os
import re
import resource
import shutil
import subprocess
import sys
import time
from pathlib import Path

log = logging.getLogger("bench.main_job")

ROOT = Path(__file__).resolve().parents[1]
ARGS = ["generate", "scenes/first_look.json", "--config", "first_look", "--frames", "2",
        "--variants", "day:clear,day:rain_fog,night:wet"]
#: the README's --workers
README_WORKERS = 2
#: Files that record the run itself (times, the run's options), not the data.
NOT_DATA = {"manifest.json", "journal.txt"}
PROGRESS = re.compile(r"generate: (\d+)/(\d+) item.*elapsed (?:(\d+):)?(\d+)")


def run_job(tree: Path, out: Path, workers: int | None) -> dict:
    """Run the job of ``tree`` into ``out``; wall and CPU seconds, item times, the manifest's run record."""
    shutil.rmtree(out, ignore_errors=True)
    env = {**os.environ, "PYTHONPATH": str(tree)}
    cmd = [sys.executable, "-m", "generator.cli", "-v", *ARGS, "--out", str(out)]
    if workers:
        cmd += ["--workers", str(workers)]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, cwd=tree, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode:
        log.error("%s", proc.stderr[-4000:])
        raise SystemExit(f"{tree}: the job failed (exit {proc.returncode})")
    (out.parent / f"{out.name}.log").write_text(proc.stderr, encoding="utf-8")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    items = [60 * int(m.group(3) or 0) + int(m.group(4)) for m in PROGRESS.finditer(proc.stderr)]
    runs = json.loads((out / "manifest.json").read_text())["runs"]
    return {"wall": wall, "cpu": cpu, "items": items, "run": runs[-1]}


def _data(p: Path) -> bytes:
    """The bytes of ``p`` that are data: an image's metadata without the seconds the run took."""
    if p.suffix == ".json" and p.parent.parent.name == "images":
        doc = json.loads(p.read_text(encoding="utf-8"))
        doc.pop("timings_s", None)
        return json.dumps(doc, sort_keys=True).encode()
    return p.read_bytes()


def digests(root: Path) -> dict[str, str]:
    """SHA-256 of every data file under ``root`` by relative path."""
    out = {}
    for p in sorted(root.rglob("*")):
        if p.is_file() and p.name not in NOT_DATA:
            out[str(p.relative_to(root))] = hashlib.sha256(_data(p)).hexdigest()
    return out


def timed(label: str, tree: Path, out: Path, workers: int | None) -> dict:
    """Run the job of ``tree`` into ``out/dataset``, then rename that ``out/label``."""
    r = run_job(tree.resolve(), out / "dataset", workers)
    shutil.rmtree(out / label, ignore_errors=True)
    (out / "dataset").rename(out / label)
    (out / "dataset.log").rename(out / f"{label}.log")
    report(label, r)
    return r


def report(label: str, r: dict) -> None:
    run = r["run"]
    log.info("%-9s wall %6.1f s  cpu %6.1f s  (cpu/wall %.2f)", label, r["wall"], r["cpu"], r["cpu"] / r["wall"])
    log.info("          items at %s s", r["items"])
    log.info("          town products %s; worker set-up %s s; cycles %s s", run.get("town_products_s"),
             run.get("worker_setup_s"), run.get("cycles_rgb_s"))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out", type=Path, help="folder for the datasets and logs (created)")
    ap.add_argument("--tree", type=Path, default=ROOT, help="tree to time (default: this one)")
    ap.add_argument("--baseline", type=Path, default=None, help="baseline tree, run first in the same call")
    ap.add_argument("--workers", type=int, default=README_WORKERS, help="--workers of the job (default: the README's)")
    args = ap.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    args.out.mkdir(parents=True, exist_ok=True)
    log.info("load: %s", os.getloadavg())
    results = {}
    if args.baseline is not None:
        results["baseline"] = timed("baseline", args.baseline, args.out, args.workers)
    results["tree"] = timed("tree", args.tree, args.out, args.workers)
    log.info("load: %s", os.getloadavg())
    if args.baseline is None:
        return 0
    b, t = results["baseline"], results["tree"]
    log.info("ratios tree/baseline: wall %.3f, cpu %.3f", t["wall"] / b["wall"], t["cpu"] / b["cpu"])
    db, dt = digests(args.out / "baseline"), digests(args.out / "tree")
    differ = sorted(k for k in db.keys() & dt.keys() if db[k] != dt[k])
    only = sorted(db.keys() ^ dt.keys())
    log.info("files: %d baseline, %d tree; %d differ, %d in one only", len(db), len(dt), len(differ), len(only))
    for k in (differ + only)[:20]:
        log.info("  %s %s", "differs" if k in differ else "only in one", k)
    return 0 if not differ and not only else 1


if __name__ == "__main__":
    sys.exit(main())
