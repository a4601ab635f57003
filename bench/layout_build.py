"""Time ``build_scene`` for 1x1 .. 4x4 towns and print a table.

    python bench/layout_build.py [--spec scenes/default_town.json] [--sizes 1 2 3 4] [--repeat 1]

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
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from assets_procedural import catalog  # noqa: E402
from generator.layout import assemble  # noqa: E402
from generator.spec import load_spec  # noqa: E402


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


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spec", default=str(ROOT / "scenes" / "default_town.json"))
    ap.add_argument("--sizes", type=int, nargs="+", default=[1, 2, 3, 4])
    ap.add_argument("--repeat", type=int, default=1, help="runs per size (the median is shown)")
    args = ap.parse_args(argv)
    base = load_spec(args.spec)
    print(f"spec {args.spec} (seed {base.seed}), median of {args.repeat} run(s) per size")
    head = f"{'town':>5} {'objects':>8} {'things':>7} {'protos':>7} {'triangles':>10} {'build s':>8} " \
           f"{'assets s':>9} {'layout s':>9} {'flatten s':>10} {'us/tri':>7}"
    print(head)
    print("-" * len(head))
    for n in args.sizes:
        spec = dataclasses.replace(base, town=dataclasses.replace(base.town, blocks_x=n, blocks_y=n))
        runs = [measure(spec) for _ in range(args.repeat)]
        med = {k: statistics.median(r[k] for r in runs) for k in runs[0]}
        print(f"{f'{n}x{n}':>5} {med['objects']:>8.0f} {med['things']:>7.0f} {med['prototypes']:>7.0f} "
              f"{med['triangles']:>10,.0f} {med['build']:>8.2f} {med['assets']:>9.2f} "
              f"{med['build'] - med['assets']:>9.2f} {med['flatten']:>10.3f} "
              f"{1e6 * med['build'] / max(med['triangles'], 1):>7.1f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
