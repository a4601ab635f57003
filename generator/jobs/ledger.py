"""What a ``generate`` run has finished, in memory: the state the journal (:mod:`generator.jobs.journal`) records.

O(1) to update per item: a uint32 mask of finished variants per frame number (four bytes a frame), a
set of stereo pairs per sequence, one entry per town product and per dataset product.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from generator.jobs.frameset import FrameSet
from generator.weather import TIMES, combinations

#: Every (time of day, weather) a frame can be rendered in, in a fixed order: bit ``i`` of a frame's
#: mask is ``COMBOS[i]`` (18 of them: a uint32 per frame).
COMBOS: tuple[tuple[str, str], ...] = tuple(combinations(TIMES))
_BIT = {c: i for i, c in enumerate(COMBOS)}


def combo_mask(combos) -> int:
    """The bit mask of ``combos`` ((time, weather) pairs)."""
    m = 0
    for c in combos:
        m |= 1 << _BIT[tuple(c)]
    return m


def combos_of(mask: int) -> list[tuple[str, str]]:
    return [c for i, c in enumerate(COMBOS) if mask >> i & 1]


def frames_text(frames: FrameSet) -> str:
    """``0-9,20-29`` (inclusive ranges)."""
    return ",".join(f"{a}-{b - 1}" for a, b in frames.ranges) or "-"


def parse_frames_text(text: str) -> FrameSet:
    if text == "-":
        return FrameSet()
    out = []
    for part in text.split(","):
        a, b = part.split("-")
        out.append((int(a), int(b) + 1))
    return FrameSet(out)


@dataclass
class Ledger:
    """What is finished (the journal's state, in memory: O(1) per item to update).

    Attributes
    ----------
    frame_bits : (N,) uint32
        Per frame number: the mask of the variants finished (:data:`COMBOS`); grown on demand.
    stereo : dict of str -> set of int
        Finished stereo pairs per sequence.
    towns : dict of (str, str) -> (str, dict)
        ``(sequence, product)`` -> (the frames it was made for as :func:`frames_text`, extras).
    dataset : dict of str -> str
        Dataset product -> the plan fingerprint it was made for.
    """

    frame_bits: np.ndarray = field(default_factory=lambda: np.zeros(0, np.uint32))
    stereo: dict = field(default_factory=dict)
    towns: dict = field(default_factory=dict)
    dataset: dict = field(default_factory=dict)

    @property
    def empty(self) -> bool:
        return not (self.frame_bits.any() or self.stereo or self.towns or self.dataset)

    def _grow(self, k: int) -> None:
        if k >= len(self.frame_bits):
            grown = np.zeros(max(k + 1, 2 * len(self.frame_bits), 1024), np.uint32)
            grown[:len(self.frame_bits)] = self.frame_bits
            self.frame_bits = grown

    def add_frame(self, k: int, mask: int) -> bool:
        """Mark variants ``mask`` of frame ``k`` finished; False if they already were."""
        self._grow(k)
        old = int(self.frame_bits[k])
        if old | mask == old:
            return False
        self.frame_bits[k] = old | mask
        return True

    def or_frames(self, ks: np.ndarray, masks: np.ndarray) -> None:
        """Mark variants ``masks[i]`` of frame ``ks[i]`` finished, for many frames at once."""
        if len(ks):
            if ks.min() < 0:
                raise ValueError("frame numbers are >= 0")
            self._grow(int(ks.max()))
            np.bitwise_or.at(self.frame_bits, ks, masks)

    def add_frames(self, frames: FrameSet, mask: int) -> None:
        if frames:
            self._grow(frames.max())
            for a, b in frames.ranges:
                self.frame_bits[a:b] |= np.uint32(mask)

    def _complete(self, frames: FrameSet, mask: int) -> tuple[np.ndarray, np.ndarray]:
        arr = frames.array()
        bits = np.zeros(len(arr), np.uint32)
        inside = arr < len(self.frame_bits)
        bits[inside] = self.frame_bits[arr[inside]]
        return arr, (bits & np.uint32(mask)) == np.uint32(mask)

    def frames_done(self, frames: FrameSet, mask: int) -> FrameSet:
        """The frames of ``frames`` finished in every variant of ``mask``."""
        if not frames:
            return frames
        arr, done = self._complete(frames, mask)
        return FrameSet.from_sorted(arr[done])

    def frames_left(self, frames: FrameSet, mask: int) -> FrameSet:
        """The frames of ``frames`` not finished in every variant of ``mask``."""
        if not frames:
            return frames
        arr, done = self._complete(frames, mask)
        return frames if not done.any() else FrameSet.from_sorted(arr[~done])

    def frame_done(self, k: int, mask: int) -> bool:
        return k < len(self.frame_bits) and int(self.frame_bits[k]) & mask == mask

    def add_stereo(self, seq: str, j: int) -> bool:
        done = self.stereo.setdefault(seq, set())
        if j in done:
            return False
        done.add(j)
        return True

    def add_town(self, seq: str, product: str, frames: str, extra: dict) -> bool:
        key = (seq, product)
        if self.towns.get(key) == (frames, extra):
            return False
        self.towns[key] = (frames, dict(extra))
        return True

    def town_done(self, seq: str, product: str, frames: FrameSet) -> dict | None:
        """The extras of ``product`` of sequence ``seq`` if it was made for exactly ``frames``, else None."""
        rec = self.towns.get((seq, product))
        return rec[1] if rec is not None and rec[0] == frames_text(frames) else None

    def add_dataset(self, product: str, fingerprint: str) -> bool:
        if self.dataset.get(product) == fingerprint:
            return False
        self.dataset[product] = fingerprint
        return True

    def n_images(self, frames: FrameSet, combos) -> int:
        """Finished images of the plan (``frames`` x ``combos``)."""
        mask = np.uint32(combo_mask(combos))
        arr = frames.array()
        arr = arr[arr < len(self.frame_bits)]
        bits = self.frame_bits[arr] & mask
        return int(np.unpackbits(bits.view(np.uint8)).sum())

    # -- records --
    def apply(self, record: str) -> None:
        """Apply one record (raises ValueError/KeyError/IndexError on a malformed one)."""
        parts = record.split(" ")
        kind = parts[0]
        if kind == "frame":
            self.add_frame(int(parts[1]), parse_combos(parts[2]))
        elif kind == "frames":
            a, b = parts[1].split("-")
            self.add_frames(FrameSet([(int(a), int(b) + 1)]), parse_combos(parts[2]))
        elif kind == "stereo":
            self.add_stereo(parts[1], int(parts[2]))
        elif kind == "town":
            parse_frames_text(parts[3])
            extra = dict(p.split("=", 1) for p in parts[4:])
            self.add_town(parts[1], parts[2], parts[3], extra)
        elif kind == "dataset":
            self.add_dataset(parts[1], parts[2])
        else:
            raise ValueError(f"unknown record {kind!r}")

    def records(self) -> list[str]:
        """Every record in canonical order (frames as ranges of equal masks)."""
        out = []
        bits = self.frame_bits
        nz = np.flatnonzero(bits)
        if nz.size:
            vals = bits[nz]
            brk = np.flatnonzero((np.diff(nz) != 1) | (np.diff(vals) != 0)) + 1
            for s, e in zip(np.r_[0, brk], np.r_[brk, nz.size], strict=True):
                a, b, m = int(nz[s]), int(nz[e - 1]), int(vals[s])
                out.append(f"frames {a}-{b} {combos_text(m)}")
        for seq in sorted(self.stereo, key=_seq_key):
            out += [f"stereo {seq} {j}" for j in sorted(self.stereo[seq])]
        for (seq, product), (frames, extra) in sorted(self.towns.items(),
                                                      key=lambda kv: (_seq_key(kv[0][0]), kv[0][1])):
            out.append(" ".join([f"town {seq} {product} {frames}", *(f"{k}={v}" for k, v in sorted(extra.items()))]))
        out += [f"dataset {p} {fp}" for p, fp in sorted(self.dataset.items())]
        return out


def _seq_key(seq: str):
    return (int(seq), seq) if seq.isdigit() else (-1, seq)


def combos_text(mask: int) -> str:
    return ",".join(f"{t}:{w}" for t, w in combos_of(mask))


def parse_combos(text: str) -> int:
    return combo_mask(tuple(c.split(":")) for c in text.split(","))
