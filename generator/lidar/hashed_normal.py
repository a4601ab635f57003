"""Standard normal draws hashed from a key and an index, for compiled loops (the LiDAR's range noise).

A draw is a pure function of ``(key, index)``: the same point gets the same noise whatever the
thread count, chunking or order of evaluation. The 64-bit words come from SplitMix64's finaliser of
``key ^ index * phi`` plus a word counter; a word becomes a normal by Marsaglia and Tsang's
ziggurat (256 layers of equal area under ``exp(-x^2 / 2)``, "The Ziggurat Method for Generating
Random Variables", J. Stat. Softw. 5(8), 2000): ~99 % of the draws cost one word, a multiply and a
compare; the rest take a second word (a wedge test with one ``exp``) or, beyond ``R`` = 3.654, the
exact tail (Marsaglia's exponential rejection). The draws are exactly normal up to the 52-bit
resolution of the uniform, tails included: no table truncates them.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: layers of the ziggurat, the start of its tail and the area of each layer (Marsaglia and Tsang)
LAYERS, R, AREA = 256, 3.6541528853610088, 4.92867323399e-3
_GOLDEN = 0x9E3779B97F4A7C15


def _tables() -> tuple[np.ndarray, np.ndarray]:
    """(LAYERS + 1,) float64 layer edges ``x`` (``x[0]`` the base's virtual width, ``x[1] = R``, ``x[-1] = 0``)
    and ``exp(-x^2 / 2)`` of each."""
    x = np.zeros(LAYERS + 1)
    x[0], x[1] = AREA / math.exp(-R * R / 2), R
    for k in range(1, LAYERS - 1):
        x[k + 1] = math.sqrt(-2.0 * math.log(math.exp(-x[k] * x[k] / 2) + AREA / x[k]))
    return x, np.exp(-x * x / 2)


_X, _F = _tables()


@njit(nogil=True, cache=True, inline="always")
def _word(z, j):  # pragma: no cover - compiled
    """SplitMix64's finaliser of ``z + (j + 1) * phi``: the ``j``-th 64-bit word of a draw."""
    x = z + np.uint64(j + 1) * np.uint64(_GOLDEN)
    x = (x ^ (x >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    x = (x ^ (x >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return x ^ (x >> np.uint64(31))


@njit(nogil=True, cache=True, inline="always")
def _open01(w):  # pragma: no cover - compiled
    """A 64-bit word as a uniform in (0, 1) (its top 53 bits, centred in their interval)."""
    return (np.float64(w >> np.uint64(11)) + 0.5) / 9007199254740992.0


@njit(nogil=True, cache=True)
def normal01(key, index):  # pragma: no cover - compiled
    """The standard normal draw of ``(key, index)`` (64-bit integers; see the module docstring)."""
    z = np.uint64(key) ^ (np.uint64(index) * np.uint64(_GOLDEN))
    j = 0
    while True:
        w = _word(z, j)
        j += 1
        k = np.int64(w & np.uint64(LAYERS - 1))
        sign = -1.0 if (w >> np.uint64(8)) & np.uint64(1) else 1.0
        x = np.float64(w >> np.uint64(12)) * (1.0 / 4503599627370496.0) * _X[k]  # uniform over the layer's width
        if x < _X[k + 1]:  # inside the layer below's edge: under the curve
            return sign * x
        if k == 0:  # the tail beyond R
            while True:
                a = -math.log(_open01(_word(z, j))) / R
                b = -math.log(_open01(_word(z, j + 1)))
                j += 2
                if b + b > a * a:
                    return sign * (R + a)
        # the wedge between the layer's rectangle and the curve
        if _F[k] + _open01(_word(z, j)) * (_F[k + 1] - _F[k]) < math.exp(-0.5 * x * x):
            return sign * x
        j += 1
