"""LiDAR class mix of a spec over several towns, beside SemanticKITTI's, with the TV distance.

    python bench/class_mix.py scenes/kitti_like.json [--towns 3] [--sweeps 40] [--first 0 3 6]
                              [--drive 600] [--seeds 2027 7 99] [--baseline scenes/default_town.json | none]
                              [--json out.json]

Each town is the spec with another seed (``seed + first + k``, or the ``--seeds`` given). With ``--drive N``
(what a user gets) a town's sweeps are the first N consecutive 10 Hz sweeps of its drive, cast exactly as
``urbangen lidar SPEC --frames N`` casts them: the ego on route 0 through the spec's traffic, the spec's sensor with its
return model (the HDL-64E's physical returns); the report then adds, per town, the TV and the ratio of
each class above 1 % of SemanticKITTI's points to its share there (target: within 1.5x), and the
first sweep where each of the 19 classes appears. Without it the sweeps are frames spread evenly over
one lap of route 0 (frames at the spec's spacing, every n-th), the static town, ideal returns.
Labels are mapped to SemanticKITTI's 19 learning classes.
``--first`` takes several offsets: each is one disjoint *seed set* of ``--towns``
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


def measure_drive(spec, sweeps: int) -> tuple[np.ndarray, np.ndarray]:
    """(20,) int64 points per learning class over the first ``sweeps`` sweeps of the user's drive, and
    (20,) the first sweep each class appears in (-1: never)."""
    from generator.jobs.lidar_sequence import return_model, sweep_alpha, world_for
    from generator.lidar.returns import frame_key
    from generator.scan_effects.pipeline import processing_for_spec
    from generator.world.rig import SWEEP_PERIOD_S

    lut = label_sets()["semantickitti"].from_raw[class_table().to_semantickitti]
    counts, first = np.zeros(20, np.int64), np.full(20, -1, np.int64)
    scene = build_scene(spec)
    world = world_for(spec, scene, sweeps)
    rig = Rig.from_world(spec, world)
    sensor = sensor_for_spec(spec)
    model = return_model(sensor, spec.seed)
    processing = processing_for_spec(spec, sensor)
    with Scanner(scene, sensor, threads=2, world=world, returns=model) as sc:
        for j in range(sweeps):
            kw = {} if model is None else {"alpha_per_m": sweep_alpha(spec, processing, j),
                                           "noise_key": frame_key(spec.seed, j)}
            pts = sc.sweep(rig, j * SWEEP_PERIOD_S, spec.sensors.lidar.motion_skew, **kw).points
            pts = pts[pts["echo"] == 0]
            c = np.bincount(lut[pts["class"]], minlength=20)[:20]
            first[(first < 0) & (c > 0)] = j
            counts += c
    return counts, first


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


def measure(spec_path: str, towns: int, sweeps: int, first: int = 0, drive: int = 0,
            seeds: list[int] | None = None) -> tuple[np.ndarray, float, list]:
    """(20,) point counts per learning class over ``towns`` x ``sweeps`` sweeps (or ``drive`` consecutive
    sweeps), seconds, per-town (seed, counts, first sweep per class or None). ``seeds`` given: those
    towns instead of ``seed + first + k``."""
    base = load_spec(spec_path)
    per_town = []
    t0 = time.perf_counter()
    for seed in seeds or [base.seed + k for k in range(first, first + towns)]:
        spec = dataclasses.replace(base, seed=seed)
        spec = dataclasses.replace(spec, spec_hash=canonical_hash(spec.to_dict()))
        if drive:
            per_town.append((spec.seed, *measure_drive(spec, drive)))
        else:
            per_town.append((spec.seed, measure_town(spec, sweeps), None))
        print(f"  {Path(spec_path).name} town {spec.seed} measured ({time.perf_counter() - t0:.0f} s so far)",
              file=sys.stderr, flush=True)
    return sum(t[1] for t in per_town), time.perf_counter() - t0, per_town


def share_ratios(p: np.ndarray, q: np.ndarray) -> dict[int, float]:
    """Our share over SemanticKITTI's for every class above 1 % there."""
    return {c: float(p[c] / q[c]) for c in range(1, 20) if q[c] > 0.01}


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
    ap.add_argument("--drive", type=int, default=0,
                    help="consecutive sweeps of the user's drive per town (600: one minute), instead of --sweeps "
                         "spread over a lap")
    ap.add_argument("--seeds", type=int, nargs="+",
                    help="measure exactly these town seeds (one set; replaces --towns and --first)")
    ap.add_argument("--json", help="write the counts (per set and per town) to this JSON file")
    args = ap.parse_args()
    if args.seeds:
        args.towns, args.first = len(args.seeds), [0]
    names = label_sets()["semantickitti"].names
    q = reference_distribution()
    runs = [(f"set+{f}", args.spec, f) for f in args.first]
    if args.baseline != "none":
        runs.append(("baseline", args.baseline, args.first[0]))
    rows, dump = {}, {}
    for label, path, first in runs:
        counts, secs, per_town = measure(path, args.towns, args.sweeps, first, args.drive, args.seeds)
        rows[label] = (distribution(counts), counts, secs, per_town, path, first)
        dump[label] = {"spec": str(path), "first": first, "counts": counts.tolist(), "drive": args.drive,
                       "towns": {str(t[0]): t[1].tolist() for t in per_town},
                       "first_sweep": {str(t[0]): t[2].tolist() for t in per_town if t[2] is not None}}
    labels = list(rows)
    print(f"{'class':<15} {'SemKITTI %':>10} " + " ".join(f"{lb:>10}" for lb in labels))
    for c in range(1, 20):
        print(f"{names[c]:<15} {100 * q[c]:10.2f} " + " ".join(f"{100 * rows[lb][0][c]:10.2f}" for lb in labels))
    n_sweeps = args.towns * (args.drive or args.sweeps)
    for label in labels:
        p, counts, secs, per_town, path, first = rows[label]
        towns = ", ".join(f"{t[0]}: {tv_distance(distribution(t[1]), q):.3f}" for t in per_town)
        print(f"{label:<9} {Path(path).name:<18} TV {tv_distance(p, q):.3f}  (seeds {per_town[0][0]}-"
              f"{per_town[-1][0]}, {n_sweeps} sweeps, {int(counts.sum()):,} labelled points, "
              f"{secs:.0f} s; per town {towns})")
        if args.drive:
            for seed, c, first_sweep in per_town:
                ratio = share_ratios(distribution(c), q)
                worst = max(ratio.values(), key=lambda r: max(r, 1 / max(r, 1e-9)))
                print(f"  town {seed}: TV {tv_distance(distribution(c), q):.3f}; share / SemanticKITTI's for classes "
                      f"> 1 %: " + ", ".join(f"{names[k]} {r:.2f}" for k, r in ratio.items())
                      + f" (worst {worst:.2f}; target 0.67-1.5)")
                missing = [names[k] for k in range(1, 20) if first_sweep[k] < 0]
                print("    classes appear by sweep: " + ", ".join(f"{names[k]} {first_sweep[k]}" for k in range(1, 20)
                                                                  if first_sweep[k] >= 0)
                      + (f"; never: {', '.join(missing)}" if missing else ""))
    if args.json:
        Path(args.json).write_text(json.dumps(dump, indent=1))


if __name__ == "__main__":
    main()
