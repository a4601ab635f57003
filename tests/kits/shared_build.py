"""A build made once per test run and shared by the pytest-xdist workers (a lock file; the first to ask builds).

Under ``pytest -n 2`` a session fixture runs once per worker, and a module fixture keeps every test that
uses it on one worker. :class:`SharedBuild` is for an expensive dataset that tests on *both* workers
compare against: it is built once, in the run's own temporary folder, by whichever worker asks first;
a worker asking while it is being built waits for it. A test that makes its own output first and asks
for the shared one only to compare (:meth:`SharedBuild.path` called late) runs beside the build instead
of after it.
"""

from __future__ import annotations

import fcntl
import os
import shutil
import time
from collections.abc import Callable
from pathlib import Path

DONE = ".shared-build-done"
LOG = "shared-builds.log"   #: one line per build made or waited for (:func:`summary` reads it)


class SharedBuild:
    """``build(folder)`` made once into ``<run's temporary folder>/<name>``; :meth:`path` waits for it.

    Parameters
    ----------
    tmp_path_factory : pytest.TempPathFactory
    name : str
        Folder name of the build (unique per build in the run).
    build : callable
        ``build(folder: Path) -> None``; ``folder`` does not exist yet. Its output is read-only for the tests.
    """

    def __init__(self, tmp_path_factory, name: str, build: Callable[[Path], None]):
        base = tmp_path_factory.getbasetemp()
        # the workers' folders (popen-gw0, ...) sit in this run's own folder: the place they share
        self.base = base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base
        self.folder = self.base / name
        self.build = build

    def path(self) -> Path:
        """The build's folder, made now (or waited for) if no worker has made it yet."""
        t0 = time.perf_counter()
        with open(self.base / f"{self.folder.name}.lock", "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file closes
            waited, built = time.perf_counter() - t0, 0.0
            if not (self.base / f"{self.folder.name}{DONE}").exists():
                if self.folder.exists():  # a build that failed on another worker: start again
                    shutil.rmtree(self.folder)
                self.build(self.folder)
                (self.base / f"{self.folder.name}{DONE}").touch()
                built = time.perf_counter() - t0 - waited
        if waited > 0.5 or built:
            with open(self.base / LOG, "a") as log:  # one short line: O_APPEND keeps the workers' lines whole
                log.write(f"{self.folder.name} {os.environ.get('PYTEST_XDIST_WORKER', '-')} "
                          f"waited {waited:.1f} built {built:.1f}\n")
        return self.folder


def summary(base: Path) -> list[str]:
    """Lines for the end of the run: per build, the seconds it took and the seconds workers waited for it
    (a worker waiting holds its CPU idle unless the build uses both), from ``base/shared-builds.log``."""
    try:
        rows = [line.split() for line in (Path(base) / LOG).read_text().splitlines()]
    except OSError:
        return []
    built = {r[0]: float(r[5]) for r in rows if float(r[5]) > 0}
    waited: dict[str, float] = {}
    for r in rows:
        waited[r[0]] = waited.get(r[0], 0.0) + float(r[3])
    lines = [f"{name}: built in {built.get(name, 0.0):.0f} s, waited for {waited[name]:.0f} s"
             for name in sorted(waited, key=lambda n: -waited[n])]
    return [f"shared builds: {sum(built.values()):.0f} s building, {sum(waited.values()):.0f} s waiting", *lines]
