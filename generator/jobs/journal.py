"""The journal of a ``generate`` run: every finished item, one line each, append-only.

``manifest.json`` is the dataset's summary; the journal is its bookkeeping. The parent appends one
short line per finished item (O(1): no file is rewritten while items finish), and a rerun reads the
journal instead of looking at millions of files.

Files, in ``DIR/journal/``:

``merged.log``
    The compacted state: written whole (atomically) when a run starts and when it ends.
``run-NNNNNN.log``
    One per run, appended as items finish (one ``write`` per line, no buffering: a SIGKILL loses at
    most the line being written; power loss may lose the last lines, which are then made again).

The state is the union of the records of every file (records only add; order does not matter), so
a run killed at any point -- mid-line, between writing ``merged.log`` and removing the segments it
absorbed -- reads back a state that is correct or one that redoes a few items, never one that skips
an unfinished item. A complete run ends with ``merged.log`` alone, in a canonical order: a killed and
resumed run ends with the same bytes as an uninterrupted one.

Lines are ``<record>\\t<crc32 of the record, 8 hex digits>\\n``; a line whose checksum or form is
wrong (a torn last line) is ignored: its item is made again. Records:

===================================================  ================================================
``frame K T:W[,T:W...]``                             every listed variant of image frame ``K`` is complete
``frames A-B T:W[,T:W...]``                          the same for frames ``A..B`` (``merged.log``)
``stereo NN J``                                      the stereo pair of sweep ``J`` of sequence ``NN``
``town NN PRODUCT A-B[,C-D...] [KEY=VALUE ...]``     a per-town product, made for those image frames
``dataset PRODUCT FINGERPRINT``                      a dataset product (statistics ...) for a plan
===================================================  ================================================
"""

from __future__ import annotations

import logging
import os
import re
import zlib
from pathlib import Path

import numpy as np

from generator.atomic import TMP_PREFIX, atomic_path
from generator.jobs.frameset import FrameSet
from generator.jobs.ledger import (
    COMBOS,
    Ledger,
    combo_mask,
    combos_of,
    combos_text,
    frames_text,
    parse_combos,
    parse_frames_text,
)

__all__ = ["COMBOS", "Journal", "Ledger", "combo_mask", "combos_of", "frames_text", "line", "parse_frames_text",
           "parse_line"]

log = logging.getLogger(__name__)

DIR = "journal"
MERGED = "merged.log"
HEADER = "urbangen-journal 1"
_RUN = re.compile(r"run-([0-9]{6})\.log")
def line(record: str) -> bytes:
    """One journal line: the record, a tab, its CRC-32 (8 hex digits), a newline."""
    body = record.encode("utf-8")
    return body + b"\t" + f"{zlib.crc32(body):08x}".encode() + b"\n"


def parse_line(raw: bytes) -> str | None:
    """The record of a journal line, or None if it is torn or damaged."""
    if not raw.endswith(b"\n"):
        return None
    body, sep, crc = raw[:-1].rpartition(b"\t")
    if not sep or len(crc) != 8:
        return None
    try:
        return body.decode("utf-8") if int(crc, 16) == zlib.crc32(body) else None
    except ValueError:
        return None


class Journal:
    """The journal folder of dataset ``out`` (see the module docstring).

    Parameters
    ----------
    out : path-like
        The dataset folder.
    """

    def __init__(self, out: str | os.PathLike):
        self.dir = Path(out) / DIR
        self.ledger = Ledger()
        self._fd: int | None = None
        self.damaged = 0
        #: whether ``merged.log`` alone no longer says everything (records, run segments, a ledger set from outside)
        self.dirty = True
        self.loaded = False  # the ledger was read from the journal's files (not set from outside)

    # -- reading --
    def segments(self) -> list[Path]:
        """``merged.log`` and the run segments, in order."""
        if not self.dir.is_dir():
            return []
        runs = sorted(p for p in self.dir.iterdir() if _RUN.fullmatch(p.name) and p.is_file())
        merged = self.dir / MERGED
        return ([merged] if merged.is_file() else []) + runs

    def exists(self) -> bool:
        return bool(self.segments())

    def load(self) -> Ledger:
        """Read every segment into :attr:`ledger` (damaged lines are skipped and counted).

        Single-frame lines, the bulk of a killed run's segment, take a fast path: parsed as bytes and
        applied to the ledger in one vectorised step per segment (a million lines in a few seconds).
        """
        self.ledger, self.damaged = Ledger(), 0
        masks: dict[bytes, int] = {}
        for seg in self.segments():
            ks, ms = [], []
            pieces = seg.read_bytes().split(b"\n")
            if pieces[-1]:  # a torn last line (no newline)
                self.damaged += 1
            for raw in pieces[:-1]:
                body, sep, crc = raw.rpartition(b"\t")
                try:
                    if not sep or len(crc) != 8 or int(crc, 16) != zlib.crc32(body):
                        raise ValueError
                    if body.startswith(b"frame "):
                        _, k, combos = body.split(b" ")
                        mask = masks.get(combos)
                        if mask is None:
                            mask = masks[combos] = parse_combos(combos.decode("ascii"))
                        ks.append(int(k))
                        ms.append(mask)
                        continue
                    rec = body.decode("utf-8")
                    if not rec.startswith("urbangen-journal "):
                        self.ledger.apply(rec)
                except (ValueError, KeyError, IndexError, UnicodeDecodeError):
                    self.damaged += 1
            self.ledger.or_frames(np.asarray(ks, np.int64), np.asarray(ms, np.uint32))
        if self.damaged:
            log.warning("%s: %d damaged journal line(s) (a killed run's last line): their items are made again",
                        self.dir, self.damaged)
        self.dirty = self.damaged > 0 or [p.name for p in self.segments()] != [MERGED]
        self.loaded = True
        return self.ledger

    def settle(self, max_runs: int = 8) -> None:
        """At the start of a run: write the state when no file holds it (a ledger looked up file by file), or
        compact when many killed runs left segments; otherwise leave the files (a resume stays quick)."""
        runs = [p for p in self.segments() if p.name != MERGED]
        if (not self.loaded and not self.ledger.empty) or len(runs) >= max_runs:
            self.compact()

    # -- writing --
    def compact(self) -> Path:
        """Write the ledger as ``merged.log`` (atomically, synced) and remove the run segments it absorbed.
        The current run's segment, if open, is closed first (a later record opens a new one)."""
        self.close()
        absorbed = [p for p in self.segments() if p.name != MERGED]
        if not self.dirty and not absorbed and (self.dir / MERGED).is_file():
            return self.dir / MERGED  # already the whole state: not rewritten
        self.dir.mkdir(parents=True, exist_ok=True)
        for tmp in self.dir.glob(TMP_PREFIX + "*"):
            tmp.unlink(missing_ok=True)
        path = self.dir / MERGED
        with atomic_path(path) as tmp:
            with open(tmp, "wb") as f:
                f.write(line(HEADER))
                f.writelines(line(r) for r in self.ledger.records())
                f.flush()
                os.fsync(f.fileno())
        _sync_dir(self.dir)
        for p in absorbed:
            p.unlink(missing_ok=True)
        self.dirty = False
        return path

    def _open(self) -> int:
        if self._fd is None:
            self.dir.mkdir(parents=True, exist_ok=True)
            numbers = [int(m.group(1)) for p in self.segments() if (m := _RUN.fullmatch(p.name))]
            path = self.dir / f"run-{max(numbers, default=0) + 1:06d}.log"
            self._fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o644)
            os.write(self._fd, line(HEADER))
        return self._fd

    def _append(self, record: str) -> None:
        self.dirty = True
        os.write(self._open(), line(record))

    def close(self) -> None:
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None

    def record_frame(self, k: int, combos) -> bool:
        """Variants ``combos`` of frame ``k`` are complete; False (nothing written) if already recorded."""
        mask = combo_mask(combos)
        if not self.ledger.add_frame(int(k), mask):
            return False
        self._append(f"frame {int(k)} {combos_text(mask)}")
        return True

    def record_stereo(self, seq: str, j: int) -> bool:
        if not self.ledger.add_stereo(seq, int(j)):
            return False
        self._append(f"stereo {seq} {int(j)}")
        return True

    def record_town(self, seq: str, product: str, frames: FrameSet, **extra) -> bool:
        text = frames_text(frames)
        extra = {k: str(v) for k, v in extra.items()}
        if any(" " in v or "=" in k for k, v in extra.items()):
            raise ValueError(f"journal extras must be words: {extra}")
        if not self.ledger.add_town(seq, product, text, extra):
            return False
        self._append(" ".join([f"town {seq} {product} {text}", *(f"{k}={v}" for k, v in sorted(extra.items()))]))
        return True

    def record_dataset(self, product: str, fingerprint: str) -> bool:
        if not self.ledger.add_dataset(product, fingerprint):
            return False
        self._append(f"dataset {product} {fingerprint}")
        return True

    def remove(self) -> None:
        """Drop the journal (a folder being started afresh)."""
        self.close()
        for p in self.segments():
            p.unlink(missing_ok=True)


def _sync_dir(path: Path) -> None:
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)
