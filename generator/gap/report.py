"""From measured datasets to ``gap.json``: every metric as one curve per dataset and a distance per pair.

Each entry of :data:`METRICS` names what it shows, its x axis, how a dataset's curve is computed from
its :class:`~generator.gap.profile.Profile`, and which distance compares two of them (total variation or
Wasserstein-1, :mod:`generator.gap.distances`; the JSON says which, and in what unit). Distances are
symmetric; the pairs are every dataset against the reference (default: the last one named), or every
pair (``--pairwise``), so a third dataset (a physics-based sensor) is one more argument.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from generator.gap import distances as D
from generator.gap import profile as PR
from generator.labels.sets import label_sets


def _centres(edges: np.ndarray) -> list[float]:
    return [float(v) for v in (edges[:-1] + edges[1:]) / 2]


def _rays(p: PR.Profile) -> np.ndarray:
    folded = getattr(p, "ring_rays", None)  # set by fold_rings
    return p.rays_per_ring * p.scans if folded is None else folded


#: Metrics whose curve is per ring: folded to a common ring count when the sensors differ.
PER_RING = ("rays_lost_per_ring", "ring_regularity")


def fold_rings(p: PR.Profile, n: int) -> PR.Profile:
    """A copy of ``p`` whose per-ring counts are summed into ``n`` rings by normalised ring index.

    Ring ``r`` of ``p.rings`` goes to ``r * n // p.rings`` (0 = highest beam in both): an HDL-64E's rings
    two at a time against an HDL-32E. Each folded ring keeps the rays of the rings it holds, so loss rates
    stay rays-weighted and every folded ring holds the same share of the sensor's rays.
    """
    import copy

    q = copy.copy(p)
    group = (np.arange(p.rings) * n) // p.rings
    q.rings = n
    q.ring_points = np.bincount(group, p.ring_points, minlength=n).astype(np.int64)
    q.ring_rays = np.bincount(group, _rays(p), minlength=n).astype(np.int64)
    q.residual = np.zeros((n, p.residual.shape[1]), np.int64)
    np.add.at(q.residual, group, p.residual)
    return q


def _ring_lost(p: PR.Profile) -> np.ndarray:
    return np.maximum(_rays(p) - p.ring_points, 0)


def _median_from_hist(h: np.ndarray, edges: np.ndarray) -> float | None:
    total = h.sum()
    if total <= 0:
        return None
    i = int(np.searchsorted(np.cumsum(h), total / 2.0))
    return float((edges[i] + edges[i + 1]) / 2)


def _cars(p: PR.Profile) -> np.ndarray:
    return p.object_classes.get("car", np.zeros_like(p.objects))


def _object_medians(hist: np.ndarray) -> list:
    return [None if m is None else float(10 ** m) for m in
            (_median_from_hist(row, PR.LOG_POINTS_EDGES) for row in hist)]


def _objects_w1(ha: np.ndarray, hb: np.ndarray) -> float | None:
    weights = ha.sum(1) / max(ha.sum(), 1) + hb.sum(1) / max(hb.sum(), 1)
    num = den = 0.0
    for i, w in enumerate(weights):
        d = D.w1(ha[i], hb[i], PR.LOG_POINTS_EDGES)
        if d is not None:
            num, den = num + w * d, den + w
    return num / den if den else None


def _class_w1(a: PR.Profile, b: PR.Profile) -> float | None:
    if not (a.labelled and b.labelled):
        return None
    pa, pb = a.intensity[1:].sum(1), b.intensity[1:].sum(1)
    weights = pa / max(pa.sum(), 1) + pb / max(pb.sum(), 1)
    num = den = 0.0
    for c in range(1, PR.N_LEARNING):
        d = D.w1(a.intensity[c], b.intensity[c], PR.INTENSITY_EDGES)
        if d is not None:
            num, den = num + weights[c - 1] * d, den + weights[c - 1]
    return num / den if den else None


@dataclass(frozen=True)
class Metric:
    """One measured difference."""

    what: str
    x: str
    x_values: Callable
    curve: Callable       # Profile -> list of numbers (None where undefined)
    distance: Callable    # (Profile, Profile) -> float or None
    kind: str             # "total variation" | "wasserstein-1"
    unit: str
    needs: str = ""       # "labels" | "objects" | ""


_LEARN = label_sets()["semantickitti"].names
METRICS: dict[str, Metric] = {
    "rays_lost_per_ring": Metric(
        "share of the rays of each ring without a return (rays = columns x scans; points per ring from the ring fit)",
        "ring (0 = highest beam)", lambda p: list(range(p.rings)),
        lambda p: [None if t == 0 else 1.0 - min(float(n) / float(t), 1.0)  # None: no ray of the ring in the window
                   for n, t in zip(p.ring_points, _rays(p), strict=True)],
        lambda a, b: D.tv_rates(_ring_lost(a), _rays(a), _ring_lost(b), _rays(b)),
        "total variation", "share (= mean absolute difference of the per-ring loss rates)"),
    "rays_lost_per_range": Metric(
        "share of rays lost among rays with a surface within 4 columns of the same ring, by that surface's range",
        "range, m", lambda p: _centres(PR.LOST_RANGE_EDGES),
        lambda p: [None if t == 0 else float(lo / t)
                   for lo, t in zip(p.lost_range, p.lost_range + p.returned_range, strict=True)],
        lambda a, b: D.tv_rates(a.lost_range, a.lost_range + a.returned_range, b.lost_range,
                                b.lost_range + b.returned_range),
        "total variation", "share (joint distribution of range bin and lost/returned)"),
    "points_per_range": Metric(
        "points per scan in each 2 m range bin", "range, m", lambda p: _centres(PR.RANGE_EDGES),
        lambda p: (p.range_hist / max(p.scans, 1)).tolist(), lambda a, b: D.tv(a.range_hist, b.range_hist),
        "total variation", "share of points"),
    "ring_regularity": Metric(
        "median distance of a point's range from the median of the 5 consecutive points of its ring (per ring); "
        "distance over all rings pooled", "ring (0 = highest beam)", lambda p: list(range(p.rings)),
        lambda p: [_median_from_hist(h, PR.RESIDUAL_EDGES) for h in p.residual],
        lambda a, b: D.w1(a.residual.sum(0), b.residual.sum(0), PR.RESIDUAL_EDGES),
        "wasserstein-1", "m"),
    "ring_fit_vertical": Metric(
        "share of points by vertical distance from the cone of the laser they were assigned to",
        "vertical distance, m", lambda p: _centres(PR.VERTICAL_EDGES),
        lambda p: (p.vertical / max(p.vertical.sum(), 1)).tolist(),
        lambda a, b: D.w1(a.vertical, b.vertical, PR.VERTICAL_EDGES), "wasserstein-1", "m"),
    "intensity": Metric(
        "share of points by remission (0.01 bins)", "remission", lambda p: _centres(PR.INTENSITY_EDGES),
        lambda p: (p.intensity.sum(0) / max(p.intensity.sum(), 1)).tolist(),
        lambda a, b: D.w1(a.intensity.sum(0), b.intensity.sum(0), PR.INTENSITY_EDGES),
        "wasserstein-1", "remission"),
    "intensity_per_class": Metric(
        "mean remission per SemanticKITTI class; distance: the W1 of each class's remission histogram, "
        "averaged with the classes' mean point shares", "class", lambda p: list(_LEARN[1:]),
        lambda p: [None if h.sum() == 0 else float((h * np.array(_centres(PR.INTENSITY_EDGES))).sum() / h.sum())
                   for h in p.intensity[1:]],
        _class_w1, "wasserstein-1", "remission", "labels"),
    "class_mix": Metric(
        "share of labelled points per SemanticKITTI learning class", "class", lambda p: list(_LEARN[1:]),
        lambda p: (p.intensity[1:].sum(1) / max(p.intensity[1:].sum(), 1)).tolist(),
        lambda a, b: D.tv(a.intensity[1:].sum(1), b.intensity[1:].sum(1)), "total variation", "share of points",
        "labels"),
    "points_per_object": Metric(
        "median points per object by distance of its centre; distance: the W1 of log10(points per object) "
        "in each distance bin, averaged with the bins' mean object shares", "distance, m",
        lambda p: _centres(PR.OBJECT_DISTANCE_EDGES), lambda p: _object_medians(p.objects),
        lambda a, b: _objects_w1(a.objects, b.objects), "wasserstein-1", "log10(points)", "objects"),
    "points_per_car": Metric(
        "points_per_object for cars only (box type or SemanticKITTI class car)", "distance, m",
        lambda p: _centres(PR.OBJECT_DISTANCE_EDGES), lambda p: _object_medians(_cars(p)),
        lambda a, b: _objects_w1(_cars(a), _cars(b)), "wasserstein-1", "log10(points)", "objects"),
}


def pairs_of(names: list[str], reference: str, pairwise: bool) -> list[tuple[str, str]]:
    """Which datasets are compared: each against ``reference``, or every pair."""
    if pairwise:
        return [(a, b) for i, a in enumerate(names) for b in names[i + 1:]]
    return [(a, reference) for a in names if a != reference]


def summarize(profiles: dict[str, PR.Profile], pairs: list[tuple[str, str]], objects_from: str | None) -> dict:
    """The ``metrics`` part of ``gap.json``."""
    out = {}
    rings = {p.rings for p in profiles.values()}
    n = min(rings)
    folded = {k: fold_rings(p, n) for k, p in profiles.items()} if len(rings) > 1 else profiles
    for key, m in METRICS.items():
        if m.needs == "labels" and not all(p.labelled for p in profiles.values()):
            out[key] = {"what": m.what, "skipped": "not every dataset has labels"}
            continue
        if m.needs == "objects" and objects_from is None:
            out[key] = {"what": m.what, "skipped": "no objects: neither boxes nor instance labels in every dataset"}
            continue
        use = folded if key in PER_RING else profiles
        first = next(iter(use.values()))
        entry = {"what": m.what, "x": m.x, "x_values": m.x_values(first),
                 "curves": {name: _clean(m.curve(p)) for name, p in use.items()},
                 "distance": {"kind": m.kind, "unit": m.unit,
                              "values": {f"{a} vs {b}": m.distance(use[a], use[b]) for a, b in pairs}}}
        if use is not profiles:
            entry["x"] = (f"ring, normalised to {n} rings (0 = highest beam; a sensor with more rings has them "
                          "summed in order, e.g. an HDL-64E's two at a time)")
            entry["rings_folded_from"] = {name: p.rings for name, p in profiles.items()}
        if m.needs == "objects":
            entry["objects_from"] = objects_from
        out[key] = entry
    return out


def _clean(values) -> list:
    return [None if v is None or not np.isfinite(v) else float(v) for v in values]
