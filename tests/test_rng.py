"""Named sub-streams of a builder's generator (generator.rng.substream): a feature added to an asset
builder draws its own numbers without moving the builder's."""

from __future__ import annotations

import numpy as np

from generator.rng import stream, substream


def test_a_substream_leaves_its_parent_where_it_was_and_depends_only_on_the_seed():
    g = stream(7, "assets", "building", 3)
    first = substream(g, "facade_trim").random(4)
    after = g.random(3)
    assert np.array_equal(after, stream(7, "assets", "building", 3).random(3)), "the parent was drawn from"
    assert np.array_equal(substream(g, "facade_trim").random(4), first), "depends on how far g was drawn"


def test_substreams_differ_by_name_and_by_parent():
    g = stream(7, "assets", "building", 3)
    a, b = substream(g, "facade_trim").random(4), substream(g, "shop_signs").random(4)
    c = substream(stream(7, "assets", "building", 4), "facade_trim").random(4)
    d = substream(np.random.default_rng(7), "facade_trim").random(4)
    assert len({tuple(x) for x in (a, b, c, d)}) == 4
