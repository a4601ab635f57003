"""Progress of long jobs: a bar on a terminal, a log line every few seconds elsewhere.

Render nodes run urbangen headless with stderr going to a log file; a tqdm bar is silent
there (it only draws on a terminal), which leaves minutes without a word. :func:`progress`
returns a tqdm bar when stderr is a terminal and otherwise a :class:`LogProgress` that logs
``desc: done/total unit (pct), rate, ETA`` on the ``urbangen.progress`` logger every
:data:`PERIOD_S` seconds and once at the end. A job shorter than that logs nothing (its result
is the line to read), and a job that fails does not claim to be done: the error stays the last
line. The command line shows that logger at INFO unless ``--quiet``.
"""

from __future__ import annotations

import logging
import sys
import time
from collections.abc import Iterable, Iterator

from tqdm import tqdm

log = logging.getLogger("urbangen.progress")

#: Seconds between two progress lines in a log.
PERIOD_S = 5.0


def _duration(seconds: float) -> str:
    seconds = max(0, int(round(seconds)))
    h, rem = divmod(seconds, 3600)
    m, s = divmod(rem, 60)
    return f"{h}:{m:02d}:{s:02d}" if h else (f"{m}:{s:02d}" if m else f"{s} s")


class LogProgress:
    """A tqdm-like counter that writes progress lines to the log (for stderr that is not a terminal).

    Parameters
    ----------
    iterable : iterable, optional
        Items to pass through (``total`` defaults to its length).
    total : int, optional
    desc : str
    unit : str
    period_s : float, optional
        Seconds between two lines (default :data:`PERIOD_S`).
    """

    def __init__(self, iterable: Iterable | None = None, total: int | None = None, desc: str = "", unit: str = "it",
                 period_s: float | None = None):
        self.iterable = iterable
        if total is None and iterable is not None and hasattr(iterable, "__len__"):
            total = len(iterable)
        self.total, self.desc, self.unit = total, desc, unit
        self.period_s = PERIOD_S if period_s is None else period_s
        self.n = 0
        self.start = self._last = time.monotonic()
        self._closed = False
        self._spoke = False

    def line(self, now: float | None = None) -> str:
        """The progress line as it stands."""
        now = time.monotonic() if now is None else now
        elapsed = max(now - self.start, 1e-9)
        rate = self.n / elapsed
        text = f"{self.desc}: {self.n}" + (f"/{self.total}" if self.total else "") + f" {self.unit}"
        if self.total:
            text += f" ({100.0 * self.n / self.total:.0f}%)"
        text += f", {rate:.2f} {self.unit}/s, elapsed {_duration(elapsed)}"
        if self.total and 0 < self.n < self.total and rate > 0:
            text += f", ETA {_duration((self.total - self.n) / rate)}"
        return text

    def update(self, n: int = 1) -> None:
        self.n += n
        now = time.monotonic()
        if now - self._last >= self.period_s:
            self._last = now
            self._spoke = True
            log.info("%s", self.line(now))

    def close(self) -> None:
        """The closing line, if the job lasted long enough to have progress worth a line."""
        if not self._closed:
            self._closed = True
            if self._spoke or time.monotonic() - self.start >= self.period_s:
                log.info("%s (done)", self.line())

    def __iter__(self) -> Iterator:
        for item in self.iterable:
            yield item
            self.update()
        self.close()

    def __enter__(self) -> LogProgress:
        return self

    def __exit__(self, exc_type, *exc) -> None:
        if exc_type is None:
            self.close()
        else:
            self._closed = True   # failed: the error, not "(done)", is the last line


def progress(iterable: Iterable | None = None, *, total: int | None = None, desc: str = "", unit: str = "it",
             enabled: bool = True, leave: bool = True):
    """A progress counter: tqdm on a terminal, :class:`LogProgress` otherwise, or a silent tqdm if not ``enabled``."""
    if not enabled:
        return tqdm(iterable, total=total, desc=desc, unit=unit, disable=True)
    if sys.stderr is not None and hasattr(sys.stderr, "isatty") and sys.stderr.isatty():
        return tqdm(iterable, total=total, desc=desc, unit=unit, leave=leave, smoothing=0.1)
    return LogProgress(iterable, total=total, desc=desc, unit=unit)
