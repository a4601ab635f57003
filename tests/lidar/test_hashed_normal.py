"""The range noise's hashed draws are standard normal, tails included, and a pure function of (key, index)."""

import math

import numpy as np
from numba import njit

from generator.lidar.hashed_normal import R, normal01


@njit
def _draws(key, n):
    out = np.empty(n)
    for i in range(n):
        out[i] = normal01(key, i)
    return out


def _cdf(x):
    return 0.5 * (1.0 + np.vectorize(math.erf)(x / math.sqrt(2.0)))


def test_draws_are_standard_normal_in_the_body_and_the_tails():
    n = 2_000_000
    x = _draws(12345, n)
    # Kolmogorov-Smirnov distance to the normal CDF: ~1.36 / sqrt(n) at 5 %
    s = np.sort(x[:200_000])
    ks = np.max(np.abs(_cdf(s) - (np.arange(1, len(s) + 1) - 0.5) / len(s)))
    assert ks < 1.63 / math.sqrt(len(s))  # 1 % level
    assert abs(x.mean()) < 5 / math.sqrt(n) and abs(x.std() - 1.0) < 5 / math.sqrt(2 * n)
    # the tails, where a truncated or ill-joined sampler shows: beyond 2, 3, the ziggurat's tail start R, and 4.5
    for t in (2.0, 3.0, R, 4.5):
        p = 2 * (1 - _cdf(np.array([t]))[0])
        seen = np.mean(np.abs(x) > t)
        assert abs(seen - p) < 5 * math.sqrt(p * (1 - p) / n) + 1 / n, (t, seen, p)
    assert np.abs(x).max() > 4.5  # the tail is not cut off
    # both signs equally
    assert abs(np.mean(x > 0) - 0.5) < 5 * 0.5 / math.sqrt(n)


def test_a_draw_depends_on_its_key_and_index_only():
    a, b = _draws(7, 1000), _draws(7, 1000)
    assert np.array_equal(a, b)
    assert normal01(7, 999) == a[999]  # alone, out of order: the same value
    c = _draws(8, 1000)
    assert np.corrcoef(a, c)[0, 1] ** 2 < 0.01  # another key: unrelated draws
    assert np.corrcoef(a[:-1], a[1:])[0, 1] ** 2 < 0.01  # neighbouring indices: unrelated
