"""LiDAR class mix of a spec over several towns, beside SemanticKITTI's, with the TV distance.

    python bench/class_mix.py scenes/kitti_like.json [--towns 3] [--sweeps 40] [--first 0] [--baseline scenes/default_town.json]

Each town is the spec with another seed (``seed + first + k``); the sweeps of a town are frames spread
evenly over one lap of route 0 (frames at the spec's spacing, every n-th), labels mapped to SemanticKITTI's 19 learning classes. The baseline spec
(default: the default town) is measured the same way in the same run.
"""

from __future__ import annotations

import argparse
import dataclasses
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


def measure(spec_path: str, towns: int, sweeps: int, first: int = 0) -> tuple[np.ndarray, float]:
    """(20,) point counts per learning class over ``towns`` x ``sweeps`` sweeps, and seconds."""
    base = load_spec(spec_path)
    lut = label_sets()["semantickitti"].from_raw[class_table().to_semantickitti]
    counts = np.zeros(20, np.int64)
    t0 = time.perf_counter()
    for k in range(first, first + towns):
        spec = dataclasses.replace(base, seed=base.seed + k)
        spec = dataclasses.replace(spec, spec_hash=canonical_hash(spec.to_dict()))
        scene = build_scene(spec)
        rig = Rig.from_spec(spec, scene)
        # spread the sweeps evenly over one lap of route 0 (the first few hundred metres are a
        # street or two: their cross-sections would decide the whole mix)
        idx = np.unique(np.linspace(0, rig.max_frames() - 1, sweeps).round().astype(int))
        with Scanner(scene, sensor_for_spec(spec), threads=2) as sc:
            for f in (rig.frame(int(k)) for k in idx):
                pts = sc.sweep(rig, f.t, spec.sensors.lidar.motion_skew).points
                counts += np.bincount(lut[pts["class"]], minlength=20)[:20]
    return counts, time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("spec")
    ap.add_argument("--towns", type=int, default=3)
    ap.add_argument("--sweeps", type=int, default=40,
                    help="sweeps per town, spread over route 0 (default 40: 120 over 3 towns; with 17 the mix of "
                         "one spec swung by 0.08 in TV between samplings, a few streets decide it)")
    ap.add_argument("--first", type=int, default=0, help="first town's seed offset (other towns, same spec)")
    ap.add_argument("--baseline", default=str(ROOT / "scenes" / "default_town.json"))
    args = ap.parse_args()
    names = label_sets()["semantickitti"].names
    q = reference_distribution()
    rows = {}
    for label, path in (("spec", args.spec), ("baseline", args.baseline)):
        counts, secs = measure(path, args.towns, args.sweeps, args.first)
        rows[label] = (distribution(counts), counts, secs)
    print(f"{'class':<15} {'SemanticKITTI %':>15} {'spec %':>9} {'baseline %':>11}")
    for c in range(1, 20):
        print(f"{names[c]:<15} {100 * q[c]:15.2f} {100 * rows['spec'][0][c]:9.2f} {100 * rows['baseline'][0][c]:11.2f}")
    for label, path in (("spec", args.spec), ("baseline", args.baseline)):
        p, counts, secs = rows[label]
        print(f"{label:<9} {Path(path).name:<22} TV {tv_distance(p, q):.3f}  ({args.towns} towns from seed offset "
              f"{args.first}, {args.towns * args.sweeps} sweeps, "
              f"{int(counts.sum()):,} labelled points, {secs:.0f} s)")


if __name__ == "__main__":
    main()
