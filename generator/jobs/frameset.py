"""A set of frame numbers kept as ranges: the compact form of a plan's frames.

A plan of a million frames is one range, not a million integers: :class:`FrameSet` holds sorted,
disjoint, non-adjacent half-open ranges ``[start, stop)`` and behaves like a sorted sequence of
ints (``len``, iteration, ``in``, ``min``/``max``, indexing is not offered). It is written to JSON as
``[[start, stop], ...]`` (:meth:`FrameSet.to_json`) and split among workers as stepped ``range``
objects (:meth:`FrameSet.deal`), so neither the manifest nor a job ever lists every frame.
"""

from __future__ import annotations

import bisect
from collections.abc import Iterable, Iterator

import numpy as np


class FrameSet:
    """Sorted, disjoint frame ranges.

    Parameters
    ----------
    ranges : iterable of (int, int)
        Half-open ``[start, stop)`` ranges, in any order, possibly overlapping (they are merged).
    """

    __slots__ = ("_starts", "_stops", "_cum")

    def __init__(self, ranges: Iterable[tuple[int, int]] = ()):
        merged: list[list[int]] = []
        for a, b in sorted((int(a), int(b)) for a, b in ranges if int(b) > int(a)):
            if merged and a <= merged[-1][1]:
                merged[-1][1] = max(merged[-1][1], b)
            else:
                merged.append([a, b])
        self._starts = [a for a, _ in merged]
        self._stops = [b for _, b in merged]
        self._cum = np.cumsum([0] + [b - a for a, b in merged]).tolist()

    # -- construction --
    @classmethod
    def span(cls, first: int, count: int) -> FrameSet:
        """Frames ``first .. first + count - 1``."""
        return cls([(first, first + count)])

    @classmethod
    def of(cls, frames: Iterable[int]) -> FrameSet:
        """The set of the given frame numbers (any order, duplicates dropped)."""
        if isinstance(frames, FrameSet):
            return frames
        if isinstance(frames, range) and frames.step == 1:
            return cls([(frames.start, frames.stop)])
        arr = np.unique(np.fromiter((int(k) for k in frames), np.int64))
        return cls.from_sorted(arr)

    @classmethod
    def from_sorted(cls, arr: np.ndarray) -> FrameSet:
        """From a sorted array of distinct frame numbers (vectorised)."""
        arr = np.asarray(arr, np.int64)
        if arr.size == 0:
            return cls()
        breaks = np.flatnonzero(np.diff(arr) != 1) + 1
        starts = arr[np.r_[0, breaks]]
        stops = arr[np.r_[breaks - 1, arr.size - 1]] + 1
        return cls(zip(starts.tolist(), stops.tolist(), strict=True))

    @classmethod
    def from_mask(cls, mask: np.ndarray, offset: int = 0) -> FrameSet:
        """Frames ``offset + i`` where ``mask[i]`` is true (vectorised)."""
        return cls.from_sorted(np.flatnonzero(np.asarray(mask, bool)) + int(offset))

    # -- the sequence protocol --
    @property
    def ranges(self) -> list[tuple[int, int]]:
        return list(zip(self._starts, self._stops, strict=True))

    def __len__(self) -> int:
        return int(self._cum[-1])

    def __bool__(self) -> bool:
        return bool(self._starts)

    def __iter__(self) -> Iterator[int]:
        for a, b in zip(self._starts, self._stops, strict=True):
            yield from range(a, b)

    def __contains__(self, k) -> bool:
        try:
            k = int(k)
        except (TypeError, ValueError):
            return False
        i = bisect.bisect_right(self._starts, k) - 1
        return i >= 0 and k < self._stops[i]

    def __eq__(self, other) -> bool:
        if isinstance(other, FrameSet):
            return self._starts == other._starts and self._stops == other._stops
        return NotImplemented

    def __hash__(self) -> int:
        return hash((tuple(self._starts), tuple(self._stops)))

    def __repr__(self) -> str:
        shown = ", ".join(f"{a}..{b - 1}" for a, b in self.ranges[:4])
        return f"FrameSet({shown}{', ...' if len(self._starts) > 4 else ''}; {len(self)} frames)"

    def min(self) -> int:
        return self._starts[0]

    def max(self) -> int:
        return self._stops[-1] - 1

    def array(self) -> np.ndarray:
        """Every frame number, int64 (for vectorised bookkeeping; len(self) entries)."""
        if not self._starts:
            return np.zeros(0, np.int64)
        return np.concatenate([np.arange(a, b, dtype=np.int64) for a, b in self.ranges])

    # -- set algebra --
    def union(self, other: Iterable[int]) -> FrameSet:
        return FrameSet(self.ranges + FrameSet.of(other).ranges)

    @classmethod
    def _raw(cls, starts: list[int], stops: list[int]) -> FrameSet:
        """From ranges already sorted, disjoint and non-adjacent (no checks)."""
        out = cls.__new__(cls)
        out._starts, out._stops = starts, stops
        cum = [0]
        for a, b in zip(starts, stops, strict=True):
            cum.append(cum[-1] + b - a)
        out._cum = cum
        return out

    def intersection(self, lo: int, hi: int) -> FrameSet:
        """The frames in ``[lo, hi)`` (O(log n + ranges inside))."""
        i = max(bisect.bisect_right(self._stops, lo), 0)
        j = bisect.bisect_left(self._starts, hi)
        starts = [max(a, lo) for a in self._starts[i:j]]
        stops = [min(b, hi) for b in self._stops[i:j]]
        return FrameSet._raw(starts, stops)

    def without(self, mask: np.ndarray) -> FrameSet:
        """The frames ``k`` of this set whose ``mask[k]`` is false (``mask`` indexed by frame number;
        frames beyond its end count as false)."""
        if not self:
            return self
        keep = np.ones(self.max() + 1, bool)
        n = min(len(mask), len(keep))
        keep[:n] = ~np.asarray(mask[:n], bool)
        inside = np.zeros(len(keep), bool)
        for a, b in self.ranges:
            inside[a:b] = True
        return FrameSet.from_mask(keep & inside)

    # -- sharing out --
    def deal(self, parts: int) -> list[tuple[range, ...]]:
        """Deal the frames round-robin into ``parts`` non-empty parts (fewer when there are fewer frames),
        exactly as ``sorted(frames)[i::parts]`` would, each part as stepped ``range`` objects."""
        parts = max(1, min(int(parts), len(self)))
        out: list[list[range]] = [[] for _ in range(parts)]
        pos = 0
        for a, b in self.ranges:
            for i in range(parts):
                r = range(a + (i - pos) % parts, b, parts)
                if len(r):
                    out[i].append(r)
            pos += b - a
        return [tuple(p) for p in out]

    # -- JSON --
    def to_json(self) -> list[list[int]]:
        """``[[start, stop], ...]`` (half-open)."""
        return [[a, b] for a, b in self.ranges]

    @classmethod
    def from_json(cls, doc, lo: int = 0, hi: int | None = None) -> FrameSet:
        """Parse :meth:`to_json`'s form: sorted, disjoint ``[start, stop]`` int pairs in ``[lo, hi]``.

        Raises
        ------
        ValueError
            With a short reason (the caller names the file and field).
        """
        if not isinstance(doc, list):
            raise ValueError("must be a list of [start, stop] frame ranges")
        prev = lo
        for r in doc:
            if not (isinstance(r, list) and len(r) == 2 and all(type(v) is int for v in r)):
                raise ValueError("must be a list of [start, stop] frame ranges (integers)")
            a, b = r
            if not (a >= prev and b > a and (hi is None or b <= hi)):
                raise ValueError(f"must be sorted, disjoint [start, stop) ranges within {lo}..{hi}")
            prev = b
        return cls((a, b) for a, b in doc)


def iter_frames(parts: Iterable) -> Iterator[int]:
    """The frame numbers of a job's ``frames``: ints, or ranges standing for their frames."""
    for p in parts:
        if isinstance(p, range):
            yield from p
        else:
            yield int(p)


def count_frames(parts: Iterable) -> int:
    return sum(len(p) if isinstance(p, range) else 1 for p in parts)


def last_frame(parts: Iterable, default: int) -> int:
    """The largest frame of a job's ``frames`` (``default`` when there is none)."""
    tops = [p[-1] if isinstance(p, range) else int(p) for p in parts if not isinstance(p, range) or len(p)]
    return max(tops, default=default)
