"""Frame ranges (:mod:`generator.jobs.frameset`): a plan's frames without listing them."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from generator.jobs.frameset import FrameSet, count_frames, iter_frames, last_frame

frames = st.lists(st.integers(0, 500), max_size=80)


@given(frames, st.integers(1, 9))
def test_a_frameset_is_the_sorted_set_and_deals_like_slicing(ks, parts):
    fs = FrameSet.of(ks)
    want = sorted(set(ks))
    assert list(fs) == want and len(fs) == len(want) and all(k in fs for k in want) and 501 not in fs
    assert FrameSet.from_json(fs.to_json()) == fs
    dealt = fs.deal(parts)
    assert [list(iter_frames(p)) for p in dealt] == [want[i::len(dealt)] for i in range(len(dealt))]
    assert all(all(isinstance(r, range) for r in p) for p in dealt)
    if want:
        assert sum(count_frames(p) for p in dealt) == len(want) and max(last_frame(p, -1) for p in dealt) == want[-1]


@given(frames, frames)
def test_union_and_left_out_frames(a, b):
    fa = FrameSet.of(a)
    assert list(fa.union(b)) == sorted(set(a) | set(b))
    mask = np.zeros(600, bool)
    mask[b] = True
    assert list(fa.without(mask)) == sorted(set(a) - set(b))
    assert list(fa.intersection(100, 200)) == [k for k in sorted(set(a)) if 100 <= k < 200]


def test_a_million_frames_are_one_range():
    fs = FrameSet.span(0, 1_000_000)
    assert fs.to_json() == [[0, 1_000_000]] and len(fs) == 1_000_000 and fs.max() == 999_999
    assert [len(p) for p in fs.deal(3)] == [1, 1, 1] and count_frames(fs.deal(3)[0]) == 333_334


@pytest.mark.parametrize("doc", [[[3, 1]], [[0, 2], [1, 4]], [[0, "2"]], "0-3", [[0, 2_000_000]], [[-1, 2]]])
def test_bad_ranges_are_refused(doc):
    with pytest.raises(ValueError):
        FrameSet.from_json(doc, 0, 1_000_000)
