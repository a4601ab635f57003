"""Districts are drawn balanced: a town gets each district in proportion to its weight.

With i.i.d. draws a 3x3 town could put most of its nine blocks in one district and the class mix
of one spec swung from town to town (issue 13, ``bench/class_mix.py``). Each group of slots (the
blocks, the outer sections) now holds every district ``floor`` or ``ceil`` of its share of the
group, while each slot keeps the weight share as its probability.
"""

from __future__ import annotations

import dataclasses
from collections import Counter

import numpy as np
import pytest

from generator.layout.lots.districts import NAMES, draw_districts
from generator.spec import load_spec

WEIGHTS = {"row_houses": 2.0, "detached": 3.0, "light_industry": 2.0, "park_edge": 0.5}


@pytest.fixture(scope="module")
def spec(root):
    base = load_spec(root / "scenes" / "kitti_like.json")
    return dataclasses.replace(base, streets=dataclasses.replace(base.streets, districts=WEIGHTS))


@pytest.mark.parametrize("groups", [(9, 28), (4, 20), (1, 3)])
def test_every_group_holds_each_district_by_its_share(spec, groups):
    total = sum(WEIGHTS.values())
    for seed in range(40):
        names = draw_districts(dataclasses.replace(spec, seed=seed), sum(groups), groups)
        start = 0
        for m in groups:
            got = Counter(names[start:start + m])
            start += m
            assert set(got) <= set(WEIGHTS)
            for name, w in WEIGHTS.items():
                share = m * w / total
                assert np.floor(share) <= got.get(name, 0) <= np.ceil(share), (seed, groups, name, got)


def test_each_slot_keeps_the_weight_share_as_its_probability(spec):
    n, seeds = 9, 3000
    counts = np.zeros((n, len(NAMES)))
    for seed in range(seeds):
        for k, name in enumerate(draw_districts(dataclasses.replace(spec, seed=seed), n)):
            counts[k, NAMES.index(name)] += 1
    p = np.array([WEIGHTS.get(name, 0.0) for name in NAMES]) / sum(WEIGHTS.values())
    assert np.abs(counts / seeds - p).max() < 0.035   # ~4 sigma of 3000 draws; i.i.d. in slot order would also pass
    assert counts[:, NAMES.index("mixed")].sum() == 0  # weight 0: never drawn


def test_groups_must_cover_the_slots(spec):
    with pytest.raises(ValueError, match="do not add up"):
        draw_districts(spec, 10, (4, 5))
    assert draw_districts(dataclasses.replace(spec, streets=None), 5) == [""] * 5
