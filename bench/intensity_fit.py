"""``urbangen intensity fit`` against a per-point Python Welford loop, on the same scans, in one run.

    python bench/intensity_fit.py [--dataset DIR] [--scans 8] [--points 120000] [--baseline-scans 2]

Without ``--dataset`` a synthetic SemanticKITTI-layout dataset is written to a temporary
folder (SemanticKITTI-like class mix, normal remission per class, ~120k points per scan).

Methods (both read the same .bin/.label files with the same reader):

* ours: :func:`generator.remission.fit.fit_dataset` -- per scan three ``np.bincount``
  calls and a vectorised Chan merge;
* Welford (published): the KITTI-CARLA converter's loop as published -- for every point,
  index the numpy arrays, map the label through SemanticKITTI's ``learning_map`` and do one
  Welford update (``for pt in range(len(scan.points))``);
* Welford (lists): a tight loop over ``.tolist()`` values per raw id, no lookup -- the
  fastest plain-Python form, a stricter baseline than the published one.

The Python loops run once on the first ``--baseline-scans`` scans only (they are slow); ours
runs three times on all scans (median reported). The speed-up compares points/s. Files are
read once beforehand so every method reads from the page cache. The results are checked equal.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from generator.formats import semantickitti as sk  # noqa: E402
from generator.labels import class_table  # noqa: E402
from generator.remission.fit import accumulate, fit_dataset  # noqa: E402

#: raw id: (share of points, mean, std) -- roughly SemanticKITTI's mix
MIX = {40: (0.22, 0.30, 0.09), 48: (0.12, 0.30, 0.10), 50: (0.15, 0.30, 0.14), 70: (0.25, 0.30, 0.16),
       72: (0.10, 0.34, 0.10), 10: (0.06, 0.33, 0.18), 80: (0.02, 0.22, 0.19), 81: (0.01, 0.50, 0.37),
       0: (0.04, 0.15, 0.20), 60: (0.01, 0.55, 0.20), 51: (0.02, 0.30, 0.14)}


def synth(root: Path, scans: int, points: int, seed: int = 0) -> None:
    g = np.random.default_rng(seed)
    raws = np.array(list(MIX), np.uint16)
    share = np.array([v[0] for v in MIX.values()])
    for i in range(scans):
        sem = g.choice(raws, points, p=share / share.sum())
        mean = np.zeros(300)
        std = np.zeros(300)
        for r, (_, m, s) in MIX.items():
            mean[r], std[r] = m, s
        rem = np.clip(g.normal(mean[sem], std[sem]), 0, 1).astype(np.float32)
        d = root / "sequences" / "00"
        sk.write_scan(d / "velodyne" / f"{i:06d}.bin", g.normal(0, 20, (points, 3)), rem)
        sk.write_labels(d / "labels" / f"{i:06d}.label", sem, np.zeros(points, np.uint16))


def welford_published(seq: sk.Sequence, frames: list[int], learning_map: dict) -> dict:
    """The converter's inner loop as published: per point, map the label through ``learning_map``
    (SemanticKITTI's 19 learning classes), index the numpy arrays, one Welford update."""
    n = {k: 0 for k in set(learning_map.values())}
    mean = dict.fromkeys(n, 0)
    m2 = dict.fromkeys(n, 0)
    for i in frames:
        pts = sk.read_scan(seq.scan_path(i))
        sem, _ = sk.read_labels(seq.label_path(i))
        rem = pts[:, 3]
        for pt in range(len(pts)):
            key = learning_map[sem[pt]]
            n[key] = n[key] + 1
            delta = rem[pt] - mean[key]
            mean[key] = mean[key] + delta / n[key]
            m2[key] = m2[key] + delta * (rem[pt] - mean[key])
    return {k: (float(mean[k]), float(np.sqrt(m2[k] / (n[k] - 1))), n[k]) for k in n if n[k] > 1}


def welford_lists(seq: sk.Sequence, frames: list[int]) -> dict:
    """The same update over Python lists (no numpy scalar overhead)."""
    n, mean, m2 = {}, {}, {}
    for i in frames:
        pts = sk.read_scan(seq.scan_path(i))
        sem, _ = sk.read_labels(seq.label_path(i))
        for key, x in zip(sem.tolist(), pts[:, 3].astype(np.float64).tolist(), strict=False):
            c = n.get(key, 0) + 1
            n[key] = c
            mu = mean.get(key, 0.0)
            delta = x - mu
            mu += delta / c
            mean[key] = mu
            m2[key] = m2.get(key, 0.0) + delta * (x - mu)
    return {k: (mean[k], float(np.sqrt(m2[k] / (n[k] - 1))), n[k]) for k in n}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--dataset", type=Path, default=None, help="existing dataset (default: synthetic)")
    ap.add_argument("--sequence", default="00")
    ap.add_argument("--scans", type=int, default=8, help="synthetic scans")
    ap.add_argument("--points", type=int, default=120_000, help="synthetic points per scan")
    ap.add_argument("--baseline-scans", type=int, default=2, help="scans the Python loops process")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory(prefix="ug-fitbench-") as tmp:
        root = args.dataset
        if root is None:
            root = Path(tmp)
            synth(root, args.scans, args.points)
        seq = sk.Sequence(root, args.sequence)
        # warm the page cache so every method reads from memory
        for i in seq.frames:
            seq.scan_path(i).read_bytes(), seq.label_path(i).read_bytes()
        times = []
        for _ in range(3):  # the first call also pays imports and allocator warm-up; report the median
            t = time.perf_counter()
            prof, summary = fit_dataset(root, [args.sequence], progress=False)
            times.append(time.perf_counter() - t)
        t_ours = float(np.median(times))
        base = seq.frames[: args.baseline_scans]
        n_base = sum(seq.scan_path(i).stat().st_size // 16 for i in base)
        learning_map = {int(k): int(v) for k, v in class_table().sk_config["learning_map"].items()}
        t = time.perf_counter()
        ref_pub = welford_published(seq, base, learning_map)
        t_pub = time.perf_counter() - t
        t = time.perf_counter()
        ref_list = welford_lists(seq, base)
        t_list = time.perf_counter() - t
        # equality on the baseline scans: refit those only
        sub, moments = fit_part(root, args.sequence, base)
        worst = max(max(abs(sub.semantickitti[k].mean - ref_list[k][0]), abs(sub.semantickitti[k].std - ref_list[k][1]))
                    for k in ref_list)
        lut = np.zeros(len(moments.count), np.intp)
        for raw, cls in learning_map.items():
            if raw < len(lut):
                lut[raw] = cls
        learn = moments.grouped(lut, max(learning_map.values()) + 1)
        lstd = learn.std()
        worst_pub = max(max(abs(learn.mean[k] - m), abs(lstd[k] - sd)) for k, (m, sd, _) in ref_pub.items())
    rate_ours = summary["points"] / t_ours
    print(f"intensity fit on {summary['scans']} scans, {summary['points']:,} points "
          f"({'synthetic' if args.dataset is None else root})")
    print(f"{'method':<28}{'points':>12}{'seconds':>10}{'points/s':>14}{'vs ours':>10}")
    print(f"{'ours (bincount + Chan)':<28}{summary['points']:>12,}{t_ours:>10.3f}{rate_ours:>14,.0f}{1.0:>9.1f}x")
    for name, secs in (("Welford, published loop", t_pub), ("Welford, Python lists", t_list)):
        rate = n_base / secs
        print(f"{name:<28}{n_base:>12,}{secs:>10.3f}{rate:>14,.0f}{rate_ours / rate:>9.0f}x slower")
    print(f"max |ours - Welford (lists, float64)| over per-class mean and std: {worst:.2e}")
    print(f"max |ours - published loop| over per-learning-class mean and std: {worst_pub:.2e}")


def fit_part(root: Path, sequence: str, frames: list[int]):
    """Fit only ``frames`` of the sequence (a symlinked copy, so the same reader runs)."""
    with tempfile.TemporaryDirectory(prefix="ug-fitpart-") as tmp:
        src = sk.sequence_dir(root, sequence)
        dst = Path(tmp) / "sequences" / "00"
        for sub in ("velodyne", "labels"):
            (dst / sub).mkdir(parents=True)
        for i in frames:
            for sub, ext in (("velodyne", "bin"), ("labels", "label")):
                (dst / sub / f"{i:06d}.{ext}").symlink_to(src / sub / f"{i:06d}.{ext}")
        return fit_dataset(tmp, ["00"], progress=False)[0], accumulate(tmp, ["00"], progress=False)[0]


if __name__ == "__main__":
    main()
