"""LiDAR class mix of a spec over several towns, beside SemanticKITTI's, with the TV distance.

    python bench/class_mix.py scenes/kitti_like.json [--towns 3] [--sweeps 40] [--first 0 3 6]
                              [--baseline scenes/default_town.json | none] [--json out.json]

Each town is the spec with another seed (``seed + first + k``); the sweeps of a town are frames spread
evenly over one lap of route 0 (frames at the spec's spacing, every n-th), labels mapped to SemanticKITTI's
19 learning classes. ``--first`` takes several offsets: each is one disjoint *seed set* of ``--towns``
towns, measured and reported on its own (per-class table, TV of the set, TV of each town), so a mix that
only holds on one lucky set shows. The baseline spec (default: the default town) is measured the same way
in the same run, on the first set only; ``--baseline none`` skips it.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from generator.labels import class_table  # noqa: E402
from generator.labels.sets import label_sets  # noqa: E402
from generator.layout import build_scene  # noqa: E402
from generator.lidar.scan import Scanner  # noqa: E402
from generator.lidar.sensors import sensor_for_spec  # noqa: E402
from generator.spec import load_spec  # noqa: E402
from generator.spec.load import canonical_hash  # noqa: E402
from generator.stats.class_mix import distribution, reference_distribution, tv_distance  # noqa: E402
from generator.world.rig import Rig  # noqa: E402


def measure_town(spec, sweeps: int) -> np.ndarray:
    """(20,) int64 points per learning class over ``sweeps`` sweeps spread over one lap of route 0."""
    lut = label_sets()["semantickitti"].from_raw[class_table().to_semantickitti]
    counts = np.zeros(20, np.int64)
    scene = build_scene(spec)
    rig = Rig.from_spec(spec, scene)
    # spread the sweeps evenly over one lap of route 0 (the first few hundred metres are a
    # street or two: their cross-sections would decide the whole mix)
    idx = np.unique(np.linspace(0, rig.max_frames() - 1, sweeps).round().astype(int))
    with Scanner(scene, sensor_for_spec(spec), threads=2) as sc:
        for f in (rig.frame(int(k)) for k in idx):
            pts = sc.sweep(rig, f.t, spec.sensors.lidar.motion_skew).points
            counts += np.bincount(lut[pts["class"]], minlength=20)[:20]
    return counts


def measure(spec_path: str, towns: int, sweeps: int, first: int = 0) -> tuple[np.ndarray, float, list]:
    """(20,) point counts per learning class over ``towns`` x ``sweeps`` sweeps, seconds, per-town counts."""
    base = load_spec(spec_path)
    per_town = []
    t0 = time.perf_counter()
    for k in range(first, first + towns):
        spec = dataclasses.replace(base, seed=base.seed + k)
        spec = dataclasses.replace(spec, spec_hash=canonical_hash(spec.to_dict()))
        per_town.append((spec.seed, measure_town(spec, sweeps)))
    return sum(c for _, c in per_town), time.perf_counter() - t0, per_town


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("spec")
    ap.add_argument("--towns", type=int, default=3)
    ap.add_argument("--sweeps", type=int, default=40,
                    help="sweeps per town, spread over route 0 (default 40: 120 over 3 towns; with 17 the mix of "
                         "one spec swung by 0.08 in TV between samplings, a few streets decide it)")
    ap.add_argument("--first", type=int, nargs="+", default=[0],
                    help="first town's seed offset of each seed set (several: several disjoint sets)")
    ap.add_argument("--baseline", default=str(ROOT / "scenes" / "default_town.json"),
                    help="spec measured beside it on the first set ('none' to skip)")
    ap.add_argument("--json", help="write the counts (per set and per town) to this JSON file")
    args = ap.parse_args()
    names = label_sets()["semantickitti"].names
    q = reference_distribution()
    runs = [(f"set+{f}", args.spec, f) for f in args.first]
    if args.baseline != "none":
        runs.append(("baseline", args.baseline, args.first[0]))
    rows, dump = {}, {}
    for label, path, first in runs:
        counts, secs, per_town = measure(path, args.towns, args.sweeps, first)
        rows[label] = (distribution(counts), counts, secs, per_town, path, first)
        dump[label] = {"spec": str(path), "first": first, "counts": counts.tolist(),
                       "towns": {str(s): c.tolist() for s, c in per_town}}
    labels = list(rows)
    print(f"{'class':<15} {'SemKITTI %':>10} " + " ".join(f"{lb:>10}" for lb in labels))
    for c in range(1, 20):
        print(f"{names[c]:<15} {100 * q[c]:10.2f} " + " ".join(f"{100 * rows[lb][0][c]:10.2f}" for lb in labels))
    for label in labels:
        p, counts, secs, per_town, path, first = rows[label]
        towns = ", ".join(f"{s}: {tv_distance(distribution(c), q):.3f}" for s, c in per_town)
        print(f"{label:<9} {Path(path).name:<18} TV {tv_distance(p, q):.3f}  (seeds {per_town[0][0]}-"
              f"{per_town[-1][0]}, {args.towns * args.sweeps} sweeps, {int(counts.sum()):,} labelled points, "
              f"{secs:.0f} s; per town {towns})")
    if args.json:
        Path(args.json).write_text(json.dumps(dump, indent=1))


if __name__ == "__main__":
    main()
