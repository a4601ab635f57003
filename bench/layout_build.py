"""Time ``build_scene`` for 1x1 .. 4x4 towns and print a table.

    python bench/layout_build.py [--spec scenes/default_town.json] [--sizes 1 2 3 4] [--repeat 1]
                                 [--towns 3]

Every town is the spec (default: the default town) with ``blocks_x = blocks_y = n``: the
street grid, the band of lots round the outer ring road, and the ground to the horizon.
Columns:

* ``build s``  -- the whole ``build_scene`` (grid, lots, placement, assets, proxies, checks);
* ``assets s`` -- the baseline measured inside the same run: the time spent in
  ``assets_procedural.catalog.build`` making the prototype meshes (the layout cannot be
  faster than the meshes it places);
* ``layout s`` -- the rest: grid, lots, placement tests, label proxies, route verification;
* ``flatten s`` -- turning the SceneModel into the flat world triangle soup (what Embree and
  the summary read), a second baseline;
* objects, things, prototypes, triangles, and ``us/tri`` (build time per triangle).

A second table compares, in the same run, the prototype cache (:mod:`assets_procedural.proto_cache`)
cold and warm: ``cold s`` the town with an empty cache (the baseline: every mesh built),
``again s`` the same town built again in the process (a render worker, ``generate``'s second
pass: every prototype a hit), and ``town i s`` the towns 1.. of a re-drawn run
(``town.redraw_every_frames``) built one after the other after town 0, with the hit rate.
Every warm build is checked to give the cold build's digest. ``--baseline DIR`` (another
checkout, e.g. ``git archive <commit> | tar -x -C DIR``) also times the same town built by
that code in a subprocess, within the same run, printed in the ``baseline s`` column.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from assets_procedural import catalog  # noqa: E402
from assets_procedural.proto_cache import CACHE  # noqa: E402
from generator.layout import assemble  # noqa: E402
from generator.spec import load_spec  # noqa: E402
from generator.spec.towns import town_spec  # noqa: E402


class AssetTimer:
    """Accumulates the time spent in ``catalog.build`` while installed."""

    def __init__(self):
        self.seconds = 0.0
        self.calls = 0
        self._orig = catalog.build

    def __enter__(self):
        def timed(kind, rng, **params):
            t = time.perf_counter()
            try:
                return self._orig(kind, rng, **params)
            finally:
                self.seconds += time.perf_counter() - t
                self.calls += 1
        catalog.build = timed
        return self

    def __exit__(self, *exc):
        catalog.build = self._orig


def measure(spec) -> dict:
    with AssetTimer() as at:
        t0 = time.perf_counter()
        scene = assemble.build_scene(spec)
        build = time.perf_counter() - t0
    t0 = time.perf_counter()
    n_tri = len(scene.faces)
    flatten = time.perf_counter() - t0
    return {"build": build, "assets": at.seconds, "asset_calls": at.calls, "flatten": flatten,
            "objects": len(scene.objects), "things": sum(o.instance_id > 0 for o in scene.objects),
            "prototypes": len(scene.prototypes), "triangles": n_tri}


def timed_build(spec) -> tuple[float, str, int, int]:
    """(seconds, digest, cache hits, cache misses) of one ``build_scene``."""
    h0, m0 = CACHE.hits, CACHE.misses
    t0 = time.perf_counter()
    scene = assemble.build_scene(spec)
    return time.perf_counter() - t0, scene.digest(), CACHE.hits - h0, CACHE.misses - m0


BASELINE_SCRIPT = """
import dataclasses, sys, time
from generator.layout import assemble
from generator.spec import load_spec
base = load_spec(sys.argv[1])
n = int(sys.argv[2])
spec = dataclasses.replace(base, town=dataclasses.replace(base.town, blocks_x=n, blocks_y=n))
t0 = time.perf_counter()
scene = assemble.build_scene(spec)
print(time.perf_counter() - t0, scene.digest())
"""


def baseline_build(checkout: str, spec_path: str, n: int) -> tuple[float, str]:
    """(seconds, digest) of the n x n town built by the code in ``checkout`` (a fresh process)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env.update(PYTHONPATH=checkout, PYTHONDONTWRITEBYTECODE="1")
    out = subprocess.run([sys.executable, "-c", BASELINE_SCRIPT, spec_path, str(n)], cwd=checkout, env=env,
                         capture_output=True, text=True, check=True).stdout.split()
    return float(out[0]), out[1]


def cache_table(base, sizes: list[int], towns: int, baseline: str | None = None, spec_path: str = "") -> None:
    """Cold vs warm builds of each size, and the towns of a re-drawn run (see the module docstring)."""
    head = (f"{'town':>5} " + (f"{'baseline s':>11} " if baseline else "") + f"{'cold s':>7} {'again s':>8} "
            + " ".join(f"{f'town {i} s':>9}" for i in range(1, towns)) + f" {'hits new town':>14}")
    print()
    print("prototype cache: cold (empty cache) vs warm, same process")
    print(head)
    print("-" * len(head))
    for n in sizes:
        spec = dataclasses.replace(base, town=dataclasses.replace(base.town, blocks_x=n, blocks_y=n))
        if baseline:
            old_s, old_digest = baseline_build(baseline, spec_path, n)
        CACHE.clear()
        cold, digest, _, _ = timed_build(spec)
        if baseline and old_digest != digest:
            print(f"  note: the baseline builds another {n}x{n} town (digest {old_digest[:12]} vs {digest[:12]})")
        again, digest2, _, _ = timed_build(spec)
        assert digest2 == digest, "a warm build changed the scene"
        redraw = dataclasses.replace(spec, town=dataclasses.replace(spec.town, redraw_every_frames=1))
        timed_build(town_spec(redraw, 0))
        rows, hits, calls = [], 0, 0
        for i in range(1, towns):
            s, _, h, m = timed_build(town_spec(redraw, i))
            rows.append(s)
            hits, calls = hits + h, calls + h + m
        print(f"{f'{n}x{n}':>5} " + (f"{old_s:>11.2f} " if baseline else "") + f"{cold:>7.2f} {again:>8.2f} "
              + " ".join(f"{s:>9.2f}" for s in rows) + f" {f'{100 * hits / max(calls, 1):.0f} %':>14}", flush=True)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spec", default=str(ROOT / "scenes" / "default_town.json"))
    ap.add_argument("--sizes", type=int, nargs="+", default=[1, 2, 3, 4])
    ap.add_argument("--repeat", type=int, default=1, help="runs per size (the median is shown)")
    ap.add_argument("--towns", type=int, default=3, help="towns of the re-drawn run in the cache table (0: no table)")
    ap.add_argument("--baseline", default=None, help="another checkout whose build is timed beside (see above)")
    ap.add_argument("--skip-breakdown", action="store_true", help="only the cache table")
    args = ap.parse_args(argv)
    base = load_spec(args.spec)
    print(f"spec {args.spec} (seed {base.seed}), median of {args.repeat} run(s) per size")
    head = f"{'town':>5} {'objects':>8} {'things':>7} {'protos':>7} {'triangles':>10} {'build s':>8} " \
           f"{'assets s':>9} {'layout s':>9} {'flatten s':>10} {'us/tri':>7}"
    print(head)
    print("-" * len(head))
    for n in [] if args.skip_breakdown else args.sizes:
        spec = dataclasses.replace(base, town=dataclasses.replace(base.town, blocks_x=n, blocks_y=n))
        runs = []
        for _ in range(args.repeat):
            CACHE.clear()  # the first table is the cold build
            runs.append(measure(spec))
        med = {k: statistics.median(r[k] for r in runs) for k in runs[0]}
        print(f"{f'{n}x{n}':>5} {med['objects']:>8.0f} {med['things']:>7.0f} {med['prototypes']:>7.0f} "
              f"{med['triangles']:>10,.0f} {med['build']:>8.2f} {med['assets']:>9.2f} "
              f"{med['build'] - med['assets']:>9.2f} {med['flatten']:>10.3f} "
              f"{1e6 * med['build'] / max(med['triangles'], 1):>7.1f}", flush=True)
    if args.towns > 0:
        cache_table(base, args.sizes, max(args.towns, 2), args.baseline, str(Path(args.spec).resolve()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
