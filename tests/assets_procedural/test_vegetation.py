"""The batched hedge is the clump-by-clump hedge, byte for byte.

``vegetation.hedge`` draws all clumps' random numbers in one block and shapes all clumps in
array operations; a hedge's bytes (and every town's digest) depend on that being the very
stream and arithmetic of building one ``_blob`` per clump in turn, which this reference does.
"""

from __future__ import annotations

import numpy as np
import pytest

from assets_procedural.vegetation import _blob, hedge
from generator.geometry import merge, on_ground


def _hedge_one_clump_at_a_time(rng, length, height=1.2, depth=0.8):
    spacing = float(rng.uniform(0.45, 0.6))
    n = max(1, int(round(length / spacing)))
    rx = length / n / 2
    xs = -length / 2 + rx + np.arange(n) * 2 * rx
    parts = []
    for x in xs:
        radii = np.array([rx * rng.uniform(1.1, 1.3), depth / 2 * rng.uniform(0.9, 1.0),
                          height / 2 * rng.uniform(0.92, 1.0)])
        c = np.array([x + rng.uniform(-0.05, 0.05) * rx, rng.uniform(-0.04, 0.04) * depth, radii[2]])
        m = _blob(rng, c, radii, "vegetation", "hedge_leaves", 0.12)
        rel = (m.vertices - c) / radii
        m.vertices = c + np.sign(rel) * np.abs(rel) ** 0.6 * radii
        reach = np.abs(m.vertices[:, 0] - c[0]).max()
        room = length / 2 - abs(c[0])
        if reach > room:
            m.vertices[:, 0] = c[0] + (m.vertices[:, 0] - c[0]) * (room / reach)
        parts.append(m)
    return on_ground(merge(parts))


@pytest.mark.parametrize("seed,length,height,depth", [(0, 0.5, 0.3, 0.2), (1, 2.3, 1.2, 0.8), (2, 7.77, 2.0, 1.5),
                                                      (3, 31.0, 4.0, 3.0), (4, 12.5, 0.9, 0.6)])
def test_batched_hedge_is_the_clump_by_clump_hedge(seed, length, height, depth):
    a = np.random.default_rng(seed)
    b = np.random.default_rng(seed)
    got = hedge(a, length, height, depth)
    want = _hedge_one_clump_at_a_time(b, length, height, depth)
    for x, y in ((got.vertices, want.vertices), (got.faces, want.faces), (got.face_class, want.face_class),
                 (got.face_material, want.face_material)):
        assert x.dtype == y.dtype and np.array_equal(x, y)
    assert a.bit_generator.state == b.bit_generator.state  # the generator is left where the loop left it
