"""Time ``build_scene`` for 1x1 .. 4x4 towns and print a table.

    python bench/layout_build.py [--spec scenes/default_town.json] [--sizes 1 2 3 4] [--repeat 1]
                                 [--towns 3] [--baseline DIR] [--skip-breakdown] [--png PATH]
    python bench/layout_build.py --profile [--spec ...] [--sizes 3]

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

A second table times, in fresh processes, the town cold (empty prototype cache
:mod:`assets_procedural.proto_cache`: every mesh built), ``again`` (the same town built again in
the process: a render worker, ``generate``'s second pass; every prototype a hit) and ``new town``
(towns 1.. of a re-drawn run, ``town.redraw_every_frames``, built one after the other after town 0:
the shared asset library is warm, the town's own buildings, fences and hedges are not), wall and
process-CPU seconds, with the prototype hit rate of the new towns. ``--baseline DIR`` (another
checkout, e.g. ``git archive HEAD~5 | tar -x -C DIR``) runs the very same measurement
with that code, alternating with this checkout's, and prints the two rows side by side; the last
column says whether this checkout built the baseline's bytes (cold town and every re-drawn town).
Every warm build is checked to give the cold build's digest. On a loaded machine compare the CPU
columns, and the two rows with each other.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from assets_procedural import catalog  # noqa: E402
from assets_procedural.proto_cache import CACHE  # noqa: E402
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


#: One measurement, run in a fresh process for this checkout and for ``--baseline`` alike (the same
#: text, only PYTHONPATH differs): the n x n town of the spec cold (empty prototype cache), again
#: (every prototype a hit), then the towns 0.. of a re-drawn run built one after the other (town 0
#: fills the cache with the shared asset library; towns 1.. are the "new town" figures). Wall and
#: process CPU seconds and the digest of every build, as JSON.
MEASURE_SCRIPT = """
import dataclasses, json, sys, time
from generator.layout import assemble
from generator.spec import load_spec
from generator.spec.towns import town_spec
try:
    from assets_procedural.proto_cache import CACHE
except ImportError:
    CACHE = None
base = load_spec(sys.argv[1])
n, towns = int(sys.argv[2]), int(sys.argv[3])
spec = dataclasses.replace(base, town=dataclasses.replace(base.town, blocks_x=n, blocks_y=n))
def build(s):
    w, c = time.perf_counter(), time.process_time()
    d = assemble.build_scene(s).digest()
    return {"wall": time.perf_counter() - w, "cpu": time.process_time() - c, "digest": d}
if CACHE is not None:
    CACHE.clear()
out = {"cold": build(spec), "again": build(spec)}
redraw = dataclasses.replace(spec, town=dataclasses.replace(spec.town, redraw_every_frames=1))
out["towns"] = [build(town_spec(redraw, 0))]
h0, m0 = (CACHE.hits, CACHE.misses) if CACHE is not None else (0, 0)
out["towns"] += [build(town_spec(redraw, i)) for i in range(1, towns)]
if CACHE is not None:
    out["cache"] = {"hits": CACHE.hits - h0, "misses": CACHE.misses - m0}
print(json.dumps(out))
"""


def measure_in(checkout: str, spec_path: str, n: int, towns: int) -> dict:
    """:data:`MEASURE_SCRIPT` run by the code in ``checkout`` (a fresh process)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env.update(PYTHONPATH=checkout, PYTHONDONTWRITEBYTECODE="1")
    out = subprocess.run([sys.executable, "-c", MEASURE_SCRIPT, spec_path, str(n), str(towns)], cwd=checkout, env=env,
                         capture_output=True, text=True, check=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def _median(runs: list[dict], pick) -> float:
    return statistics.median(pick(r) for r in runs)


def cache_table(spec_path: str, sizes: list[int], towns: int, baseline: str | None = None,
                repeat: int = 1) -> list[dict]:
    """Cold, again and new-town builds of each size, this checkout beside ``baseline`` (see the module
    docstring); the runs of the two alternate, ``repeat`` times, and the medians are shown and returned
    (one dict per size and code: ``{"n", "code", "<cold|again|new>_<wall|cpu>"}``, seconds)."""
    results = []
    print()
    print(f"cold (empty prototype cache) / again (same town, warm) / new town (towns 1..{towns - 1} of a re-drawn run, "
          f"warm); wall and CPU seconds, median of {repeat} fresh process(es) each")
    print(f"machine: {os.cpu_count()} CPUs, load average {' '.join(f'{x:.2f}' for x in os.getloadavg())} (1/5/15 min) "
          "at the start: under load compare CPU seconds, and the two rows with each other")
    head = (f"{'town':>5} {'code':>9} {'cold wall':>10} {'cpu':>6} {'again wall':>11} {'cpu':>6} "
            f"{'new town wall':>14} {'cpu':>6} {'hits':>6}  bytes")
    print(head)
    print("-" * len(head))
    for n in sizes:
        rows = {"this": []} if not baseline else {"baseline": [], "this": []}
        for _ in range(repeat):
            for code in rows:
                rows[code].append(measure_in(baseline if code == "baseline" else str(ROOT), spec_path, n, towns))
        digests = {code: [r["cold"]["digest"]] + [t["digest"] for t in r["towns"]] for code, runs in rows.items()
                   for r in runs[:1]}
        for code, runs in rows.items():
            assert all(r["again"]["digest"] == r["cold"]["digest"] for r in runs), "a warm build changed the scene"
            new = [t for r in runs for t in r["towns"][1:]]
            hits = runs[0].get("cache")
            rate = f"{100 * hits['hits'] / max(hits['hits'] + hits['misses'], 1):.0f} %" if hits else "-"
            same = ("the baseline's" if digests[code] == digests.get("baseline") else "DIFFER from the baseline") \
                if baseline and code == "this" else ""
            row = {"n": n, "code": code, "new_wall": statistics.median(t["wall"] for t in new),
                   "new_cpu": statistics.median(t["cpu"] for t in new)}
            for k in ("cold", "again"):
                row[f"{k}_wall"] = _median(runs, lambda r, k=k: r[k]["wall"])
                row[f"{k}_cpu"] = _median(runs, lambda r, k=k: r[k]["cpu"])
            results.append(row)
            print(f"{f'{n}x{n}':>5} {code:>9} {_median(runs, lambda r: r['cold']['wall']):>10.2f} "
                  f"{_median(runs, lambda r: r['cold']['cpu']):>6.2f} "
                  f"{_median(runs, lambda r: r['again']['wall']):>11.2f} "
                  f"{_median(runs, lambda r: r['again']['cpu']):>6.2f} "
                  f"{statistics.median(t['wall'] for t in new):>14.2f} "
                  f"{statistics.median(t['cpu'] for t in new):>6.2f} "
                  f"{rate:>6}  {same}",
                  flush=True)
    return results


def plot(results: list[dict], path: str, title: str) -> None:
    """Bars of :func:`cache_table`'s results to a PNG: per size, CPU seconds (left, with the 1.5 s
    target) and wall seconds (right), each code side by side."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sizes = sorted({r["n"] for r in results})
    codes = list(dict.fromkeys(r["code"] for r in results))
    fig, axes = plt.subplots(len(sizes), 2, figsize=(10, 3.8 * len(sizes)), squeeze=False)
    x = np.arange(3)
    width = 0.8 / len(codes)
    for row, n in zip(axes, sizes, strict=False):
        for ax, clock in zip(row, ("cpu", "wall"), strict=False):
            for k, code in enumerate(codes):
                r = next(r for r in results if r["n"] == n and r["code"] == code)
                v = [r[f"cold_{clock}"], r[f"again_{clock}"], r[f"new_{clock}"]]
                pos = x + (k - (len(codes) - 1) / 2) * width
                ax.bar(pos, v, width * 0.9, color=f"C{k}", label=code)
                for px, val in zip(pos, v, strict=False):
                    ax.text(px, val, f"{val:.2f}", ha="center", va="bottom", fontsize=8)
            if clock == "cpu":
                ax.axhline(1.5, color="k", lw=0.8, ls="--")
                ax.text(-0.45, 1.5, " 1.5 s target", ha="left", va="bottom", fontsize=8)
            ax.set_xticks(x, ["cold", "again", "new town"])
            ax.set_ylabel(f"{'CPU' if clock == 'cpu' else 'wall'} seconds per build_scene")
            ax.set_title(f"{title} {n}x{n}: {'process CPU' if clock == 'cpu' else 'wall clock'}", fontsize=10)
            ax.set_ylim(0, ax.get_ylim()[1] * 1.2)
            ax.legend(fontsize=8, loc="upper center", ncol=len(codes))
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def profile_new_town(spec_path: str, n: int, top: int = 25) -> None:
    """cProfile one new town (town 2 of a re-drawn run, after towns 0 and 1 warmed the cache) and print
    its top costs by own time and by cumulative time (pyinstrument is not a dependency)."""
    import cProfile
    import pstats

    from generator.spec.towns import town_spec

    base = load_spec(spec_path)
    spec = dataclasses.replace(base, town=dataclasses.replace(base.town, blocks_x=n, blocks_y=n,
                                                              redraw_every_frames=1))
    for i in (0, 1):
        assemble.build_scene(town_spec(spec, i))
    prof = cProfile.Profile()
    prof.enable()
    assemble.build_scene(town_spec(spec, 2))
    prof.disable()
    print(f"\ncProfile of a new {n}x{n} town of {Path(spec_path).stem} (town 2, warm cache):")
    stats = pstats.Stats(prof)
    stats.sort_stats("tottime").print_stats(top)
    stats.sort_stats("cumulative").print_stats(top)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spec", default=str(ROOT / "scenes" / "default_town.json"))
    ap.add_argument("--sizes", type=int, nargs="+", default=[1, 2, 3, 4])
    ap.add_argument("--repeat", type=int, default=1, help="runs per size (the median is shown)")
    ap.add_argument("--towns", type=int, default=3, help="towns of the re-drawn run in the cache table (0: no table)")
    ap.add_argument("--baseline", default=None, help="another checkout whose build is timed beside (see above)")
    ap.add_argument("--skip-breakdown", action="store_true", help="only the cache table")
    ap.add_argument("--png", default=None, help="also draw the cache table's bars to this PNG")
    ap.add_argument(
        "--profile", action="store_true", help="cProfile a new town of the first size and print the top costs"
    )
    args = ap.parse_args(argv)
    if args.profile:
        profile_new_town(args.spec, args.sizes[0])
        return 0
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
        results = cache_table(str(Path(args.spec).resolve()), args.sizes, max(args.towns, 2), args.baseline,
                              args.repeat)
        if args.png:
            plot(results, args.png, f"{Path(args.spec).stem} (load {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs)")
            print(f"wrote {args.png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
