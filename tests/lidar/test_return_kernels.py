"""The compiled waveform's cosine powers (the incidence and lobe terms of the received power)."""

import numpy as np
import pytest
from numba import njit

from generator.lidar.return_kernels import _cos_power


@njit
def _powers(c, k):
    out = np.empty_like(c)
    for i in range(c.shape[0]):
        out[i] = _cos_power(c[i], k)
    return out


@pytest.mark.parametrize("k", [1.0, 0.5, 0.25, 8.0, 400.0, 3.0, 0.3, 2.5, 1500.0])
def test_cos_power_is_pow_to_float32_rounding(k):
    c = np.concatenate([np.linspace(0.0, 1.0, 20001), np.geomspace(1e-6, 1.0, 2001)]).astype(np.float32)
    got = _powers(c, np.float32(k))
    want = c.astype(np.float64) ** k
    assert got.dtype == np.float32
    # float32 rounding: one rounding for pow and roots; a whole power by squarings compounds the
    # rounding of the base it multiplies, ~k roundings at most
    ulps = (2.0 + k) if k == int(k) and k > 1 else 4.0
    assert np.all(np.abs(got - want) <= ulps * 2.0**-24 * want + 1e-37), k
