"""Build time and peak memory of re-drawn towns: this tree against a baseline checkout, in one run.

Issue 29 gives every re-drawn town a fresh asset library of dozens of cars and people; the
prototype cache keeps a town's library build cheap. This bench builds towns ``0 .. --towns - 1`` of
the spec re-drawn every frame, one after the other in one process (as ``generate`` does), each
with its traffic world (``build_world`` for ``--seconds`` of drive), once with a baseline tree's
code (e.g. a checkout of main before the change) and once with this tree's, alternating
``--repeat`` times, each in a fresh interpreter. It prints per town the seconds of the static town
and of the traffic, and per process the peak resident memory, the prototype cache's builds
(misses) and bytes, and the distinct car and person meshes.

Usage::

    python bench/variety_build.py --baseline PATH_TO_MAIN_CHECKOUT [--spec scenes/default_town.json]
           [--towns 3] [--seconds 2] [--repeat 2]

Nothing else should run on the machine's cores meanwhile (run it through the slot lock).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: runs in the tree under test (only API that both trees have)
CHILD = r"""
import dataclasses, json, resource, sys, time
from generator.spec import load_spec
from generator.spec.towns import town_spec
from generator.layout import build_scene
from generator.traffic import build_world
from assets_procedural.proto_cache import CACHE

spec_path, n, seconds = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
base = load_spec(spec_path)
base = dataclasses.replace(base, town=dataclasses.replace(base.town, redraw_every_frames=1))
rows, meshes = [], {"car": set(), "person": set()}
for i in range(n):
    spec = town_spec(base, i)
    t0 = time.perf_counter()
    town = build_scene(spec)
    t1 = time.perf_counter()
    world = build_world(spec, town, seconds)
    t2 = time.perf_counter()
    for o in town.objects:
        if o.kind in meshes:
            meshes[o.kind].add(town.prototypes[o.prototype].vertices.tobytes())
    for a in world.actors:
        if a.kind in meshes:
            meshes[a.kind].add(world.prototypes[a.prototype].vertices.tobytes())
    rows.append({"town": i, "scene_s": t1 - t0, "world_s": t2 - t1, "misses": CACHE.misses})
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(json.dumps({"rows": rows, "peak_mb": peak, "cache_mb": CACHE.nbytes / 2**20, "misses": CACHE.misses,
                  "hits": CACHE.hits, "cars": len(meshes["car"]), "people": len(meshes["person"])}))
"""


def run(tree: Path, spec: Path, towns: int, seconds: float) -> dict:
    env = {**os.environ, "PYTHONPATH": str(tree)}
    out = subprocess.run([sys.executable, "-c", CHILD, str(spec), str(towns), str(seconds)], cwd=tree, env=env,
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", type=Path, required=True, help="a checkout of the code to compare with")
    ap.add_argument("--spec", type=Path, default=ROOT / "scenes" / "default_town.json")
    ap.add_argument("--towns", type=int, default=3)
    ap.add_argument("--seconds", type=float, default=2.0, help="traffic simulated per town")
    ap.add_argument("--repeat", type=int, default=2)
    args = ap.parse_args(argv)
    spec = args.spec.resolve()
    results: dict[str, list[dict]] = {"baseline": [], "this": []}
    for _ in range(args.repeat):
        for name, tree in (("baseline", args.baseline.resolve()), ("this", ROOT)):
            results[name].append(run(tree, spec, args.towns, args.seconds))
    print(f"{spec.name}: towns 0..{args.towns - 1} re-drawn, {args.seconds:g} s of traffic each; "
          f"best of {args.repeat} (seconds)")
    print(f"{'town':>5} | {'baseline scene':>14} {'world':>7} | {'this scene':>10} {'world':>7}")
    for i in range(args.towns):
        b = min(r["rows"][i]["scene_s"] for r in results["baseline"]), \
            min(r["rows"][i]["world_s"] for r in results["baseline"])
        t = min(r["rows"][i]["scene_s"] for r in results["this"]), min(r["rows"][i]["world_s"] for r in results["this"])
        print(f"{i:>5} | {b[0]:>14.2f} {b[1]:>7.2f} | {t[0]:>10.2f} {t[1]:>7.2f}")
    for name in ("baseline", "this"):
        r = results[name]
        total = [sum(x["scene_s"] + x["world_s"] for x in q["rows"]) for q in r]
        print(f"{name:>8}: total {min(total):.2f} s, peak RSS {max(q['peak_mb'] for q in r):.0f} MB, "
              f"cache {r[0]['cache_mb']:.0f} MB ({r[0]['misses']} builds, {r[0]['hits']} hits), "
              f"distinct car meshes {r[0]['cars']}, people {r[0]['people']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
