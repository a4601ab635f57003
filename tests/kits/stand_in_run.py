"""A ``generate`` run with stand-in tasks (:mod:`generator.jobs.dry`), as a program a test can kill.

``python -m kits.stand_in_run OUT FRAMES [--every N] [--workers W] [--kill-at POINT]`` runs
``run_generate`` on the test town with stand-in tasks (no Blender, no LiDAR); :func:`run` is the same run
in the caller's process. ``--kill-at`` makes the
parent SIGKILL itself at one point of its bookkeeping, so a test can kill it anywhere:

* ``append:N`` -- just before the N-th journal line is written;
* ``torn:N`` -- after writing the first half of the N-th journal line (a torn write);
* ``compact:N`` -- in the N-th compaction, after ``merged.log`` is in place and before the segments
  it absorbed are removed;
* ``manifest:N`` -- just after the N-th ``manifest.json`` write.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
from pathlib import Path

from kits.paths import ROOT

COMBOS = (("day", "clear"), ("night", "rain"))


def spec_with_towns(every: int | None, path: Path) -> Path:
    doc = json.loads((ROOT / "scenes" / "test_town.json").read_text())
    doc.setdefault("town", {})["redraw_every_frames"] = every
    path.write_text(json.dumps(doc))
    return path


def _die() -> None:
    os.kill(os.getpid(), signal.SIGKILL)


def arm(point: str) -> None:
    """Make this process SIGKILL itself at ``point`` (see the module docstring)."""
    from generator.jobs import journal as J
    from generator.jobs import manifest as mf

    kind, n = point.split(":")
    n, count = int(n), {"k": 0}

    def hit() -> bool:
        count["k"] += 1
        return count["k"] == n

    if kind in ("append", "torn"):
        original = J.Journal._append

        def append(self, record):
            if hit():
                if kind == "torn":
                    data = J.line(record)
                    os.write(self._open(), data[: len(data) // 2])
                _die()
            original(self, record)

        J.Journal._append = append
    elif kind == "compact":
        original_unlink = Path.unlink

        def compact(self):
            if hit():
                Path.unlink = lambda *a, **k: _die()  # merged.log is in place; the first removal dies
            try:
                return original_compact(self)
            finally:
                Path.unlink = original_unlink

        original_compact = J.Journal.compact
        J.Journal.compact = compact
    elif kind == "manifest":
        original_save = mf.save

        def save(out, manifest):
            original_save(out, manifest)
            if hit():
                _die()

        mf.save = save
    else:
        raise SystemExit(f"unknown kill point {point}")


def run(out: Path, frames: int, every: int | None = None, workers: int = 2, delay: float = 0.0) -> dict:
    """The stand-in run of ``frames`` frames into ``out`` (towns of ``every`` frames), in this process: what
    the program does when nothing kills it (a test resumes a killed run with it without starting Python)."""
    from generator.jobs.generate import GenerateOptions, run_generate
    from generator.jobs.plan import make_plan
    from generator.spec import load_spec
    from generator.spec.render import load_render_config

    out.parent.mkdir(parents=True, exist_ok=True)
    spec = load_spec(spec_with_towns(every, out.parent / f"{out.name}.spec.json"))
    return run_generate(spec, load_render_config("test"),
                        GenerateOptions(out, make_plan(frames, combos=COMBOS), workers, "local",
                                        stand_in=True, stand_in_delay_s=delay))


def main() -> None:
    p = argparse.ArgumentParser()
    p.add_argument("out", type=Path)
    p.add_argument("frames", type=int)
    p.add_argument("--every", type=int, default=None)
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--kill-at", default=None)
    p.add_argument("--delay", type=float, default=0.0)
    args = p.parse_args()
    if args.kill_at:
        arm(args.kill_at)
    run(args.out, args.frames, args.every, args.workers, args.delay)


if __name__ == "__main__":
    main()
