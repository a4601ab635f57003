"""A ``generate`` run with stand-in tasks (:mod:`generator.jobs.dry`), as a program a test can kill.

``python -m kits.stand_in_run OUT FRAMES [--every N] [--workers W] [--kill-at POINT]`` runs
``run_generate`` on the test town with stand-in tasks (no Blender, no LiDAR); :func:`run` is the same run
in the caller's process and :func:`forked` in a child forked from it. ``--kill-at`` makes the
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


def forked(out: Path, frames: int, every: int | None = None, kill_at: str | None = None,
           timeout_s: float = 300.0) -> tuple[int, str]:
    """:func:`run` in a child forked from this process, armed with ``kill_at`` (``--kill-at``); returns
    (exit code, negative for the signal that ended it; what it wrote to stdout and stderr).

    The child is the program's run without a new interpreter: it starts with what this process has
    imported (~1.2 s of imports a kill saved) and, like the program, dies alone -- the caller's state
    is its own copy. A process that has imported ``bpy`` is never forked (Blender's threads and locks do not
    survive a fork): there the run is started as its own program, as ``python -m kits.stand_in_run``."""
    import sys
    import time
    import traceback

    if "bpy" in sys.modules:
        return _spawned(out, frames, every, kill_at, timeout_s)
    out.parent.mkdir(parents=True, exist_ok=True)
    said = out.parent / f"{out.name}.output"
    pid = os.fork()
    if pid == 0:  # the child: never returns into the caller's code
        code = 1
        try:
            fd = os.open(said, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
            os.dup2(fd, 1)
            os.dup2(fd, 2)
            sys.stdout = sys.stderr = open(fd, "w", buffering=1, closefd=False)  # noqa: SIM115
            if kill_at:
                arm(kill_at)
            run(out, frames, every)
            code = 0
        except BaseException:  # noqa: BLE001 -- reported in the output, as the program would
            traceback.print_exc()
        finally:
            sys.stdout.flush()
            os._exit(code)
    deadline = time.monotonic() + timeout_s
    while not (ended := os.waitpid(pid, os.WNOHANG))[0]:
        if time.monotonic() > deadline:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            raise TimeoutError(f"the stand-in run into {out} took over {timeout_s} s")
        time.sleep(0.01)
    return os.waitstatus_to_exitcode(ended[1]), said.read_text(errors="replace")


def _spawned(out: Path, frames: int, every: int | None, kill_at: str | None, timeout_s: float) -> tuple[int, str]:
    """:func:`forked`'s run started as a new program (``python -m kits.stand_in_run``); same return value."""
    import subprocess
    import sys

    path = os.pathsep.join([str(ROOT), str(ROOT / "tests"), os.environ.get("PYTHONPATH", "")])
    env = {**os.environ, "PYTHONPATH": path}
    cmd = [sys.executable, "-m", "kits.stand_in_run", str(out), str(frames)]
    cmd += [*(["--every", str(every)] if every else []), *(["--kill-at", kill_at] if kill_at else [])]
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=timeout_s)
    return done.returncode, done.stdout + done.stderr


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
