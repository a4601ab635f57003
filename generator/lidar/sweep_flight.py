"""A sweep in flight: its output array, the actors' plan and the chained offsets of its chunks.

:class:`generator.lidar.scan.Scanner` cuts a sweep into chunks of firing columns that worker threads
cast in parallel (:meth:`~generator.lidar.scan.Scanner.submit`); the chunks of the next sweep may
already run while this one's last chunks finish, so all per-sweep state lives here, not on the scanner.
"""

from __future__ import annotations

import threading

import numpy as np


class SweepInFlight:
    """One sweep in flight: the output array, the actors' plan and the chained chunk offsets."""

    def __init__(self, out: np.ndarray, n_chunks: int, rot_t, trans, skew: bool, alpha: float = 0.0, key: int = 0):
        self.out, self.rot_t, self.trans, self.skew = out, rot_t, trans, skew
        self.alpha, self.key = alpha, key
        self.ends: list[int | None] = [None] * n_chunks
        self._done = [threading.Event() for _ in range(n_chunks)]
        self._lock = threading.Lock()
        self._pending: dict[int, tuple[np.ndarray, int]] = {}
        self._next = 0  # the first chunk whose offset is not known yet (deliver)
        self._plan, self._plan_error = None, None
        self._planned = threading.Event()

    def set_plan(self, make_plan) -> None:
        """Compute the actors' plan (``make_plan()``) and release the chunks waiting for it."""
        try:
            self._plan = make_plan()
        except Exception as e:  # noqa: BLE001 - re-raised by raise_plan_error, after the chunks stopped
            self._plan_error = e
        finally:
            self._planned.set()

    def get_plan(self):
        """The plan (None without actors); waits until it is known."""
        self._planned.wait()
        if self._plan_error is not None:
            raise RuntimeError("planning the actors of this sweep failed") from self._plan_error
        return self._plan

    def raise_plan_error(self) -> None:
        """Raise what planning raised, if anything."""
        if self._plan_error is not None:
            raise self._plan_error

    def claim(self, i: int, n: int) -> int:
        """Offset of chunk ``i``'s ``n`` points: the end of chunk ``i - 1`` (waits until it is known)."""
        start = 0
        if i > 0:
            self._done[i - 1].wait()
            start = self.ends[i - 1]
            if start is None:
                raise RuntimeError("an earlier chunk of this sweep failed")
        self.ends[i] = start + n
        self._done[i].set()
        return start

    def deliver(self, i: int, buf: np.ndarray, n: int) -> None:
        """Hand in chunk ``i``'s ``n`` points (``buf[:n]``) without waiting for the chunks before it.

        The points go to their place in :attr:`out` as soon as every earlier chunk's count is known,
        copied by whichever chunk completes the chain; a chunk finished early does not hold its thread.
        (Use either this or :meth:`claim` for all the chunks of a sweep.)
        """
        todo = []
        with self._lock:
            self._pending[i] = (buf, n)
            j = self._next
            while j in self._pending:
                b, m = self._pending.pop(j)
                start = self.ends[j - 1] if j else 0
                self.ends[j] = start + m
                todo.append((start, b, m))
                j += 1
            self._next = j
        raw = np.dtype((np.void, self.out.dtype.itemsize))  # a plain memory copy: numpy copies a packed
        for start, b, m in todo:                            # record array field by field, ~20x slower
            self.out[start:start + m].view(raw)[...] = b[:m].view(raw)

    def fail(self, i: int) -> None:
        """Release the chunks waiting on chunk ``i`` (they raise)."""
        self._done[i].set()
