"""The two distances ``gap`` reports, from histograms.

* **Total variation** ``TV(p, q) = 1/2 sum_i |p_i - q_i|`` between two normalised histograms on the same
  bins: 0 = the same distribution, 1 = disjoint. Used for categorical or binned counts (class mix,
  points per range bin) and for loss rates, as the TV between the joint distributions of
  (bin, ray returned or lost) -- :func:`tv_rates`.
* **Wasserstein-1** (earth mover's distance) between two 1-D histograms on the same bins:
  ``W1 = sum_i |P_i - Q_i| * width_i`` with ``P``, ``Q`` the cumulative shares up to the end of bin ``i``;
  in the unit of the binned quantity (metres, remission units, log10 points). Used for continuous
  quantities whose histograms may be spikes (a constant intensity), where TV would saturate at 1.

Both are 0 for a dataset against itself, exactly.
"""

from __future__ import annotations

import numpy as np


def normalised(h: np.ndarray) -> np.ndarray | None:
    """``h / h.sum()`` as float64, or None for an empty histogram."""
    h = np.asarray(h, np.float64)
    total = h.sum()
    return None if total <= 0 else h / total


def tv(p: np.ndarray, q: np.ndarray) -> float | None:
    """Total variation between two histograms (normalised here); None when either is empty."""
    p, q = normalised(p), normalised(q)
    if p is None or q is None:
        return None
    return float(0.5 * np.abs(p - q).sum())


def tv_rates(lost_a: np.ndarray, total_a: np.ndarray, lost_b: np.ndarray, total_b: np.ndarray) -> float | None:
    """TV between the joint distributions of (bin, lost or returned) of two sets of rays.

    ``lost_*`` and ``total_*`` are rays per bin. With equal ray counts per bin in both (rays per ring
    of one sensor) this is the mean absolute difference of the loss rates over the bins.
    """
    ta, tb = np.asarray(total_a, np.float64), np.asarray(total_b, np.float64)
    if ta.sum() <= 0 or tb.sum() <= 0:
        return None
    la, lb = np.asarray(lost_a, np.float64), np.asarray(lost_b, np.float64)
    pa = np.concatenate([la, ta - la]) / ta.sum()
    pb = np.concatenate([lb, tb - lb]) / tb.sum()
    return float(0.5 * np.abs(pa - pb).sum())


def w1(h_a: np.ndarray, h_b: np.ndarray, edges: np.ndarray) -> float | None:
    """Wasserstein-1 between two histograms on ``edges`` (see the module docstring); None if either is empty."""
    p, q = normalised(h_a), normalised(h_b)
    if p is None or q is None:
        return None
    return float(np.sum(np.abs(np.cumsum(p) - np.cumsum(q)) * np.diff(edges)))
