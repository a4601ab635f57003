"""Layout maps of one town per district (and a mix of street types), to look at.

    python bench/district_maps.py --out DIR [--seed 2]

For each of ``detached``, ``row_houses``, ``dense_centre``, ``light_industry`` and ``park_edge``
a 2 x 2-block town whose every block is that district, with residential streets, boulevards,
an arterial and plain streets drawn from ``streets.types``; writes ``district_<name>.png`` (the
top-down class map of :func:`generator.previews.layout_map.render_map`, 6 px per metre) and
prints, per map, the street types drawn and the objects per class that tell the districts apart.
"""

from __future__ import annotations

import argparse
import collections
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from generator.layout import build_scene  # noqa: E402
from generator.layout.network.draw import make_grid  # noqa: E402
from generator.previews.layout_map import render_map  # noqa: E402
from generator.spec import parse_spec  # noqa: E402

DISTRICTS = ("detached", "row_houses", "dense_centre", "light_industry", "park_edge")


def spec_for(district: str, seed: int):
    doc = {"name": f"district_{district}", "seed": seed,
           "town": {"blocks_x": 2, "blocks_y": 2, "block_size_m": 60, "parking_strip_width_m": 2.2,
                    "sidewalk_width_m": 2.5},
           "density": {"walls": 0.5},
           "streets": {"types": {"plain": 1, "residential": 2, "boulevard": 1, "arterial": 0.5},
                       "parking_occupancy": [0.0, 1.0], "districts": {district: 1}}}
    return parse_spec(doc, f"{district}.json")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", required=True, help="folder for the PNGs")
    ap.add_argument("--seed", type=int, default=2)
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for d in DISTRICTS:
        t0 = time.perf_counter()
        spec = spec_for(d, args.seed)
        scene = build_scene(spec)
        types = collections.Counter(s.kind for s in make_grid(spec).sections)
        kinds = collections.Counter(o.kind for o in scene.objects)
        path = out / f"district_{d}.png"
        render_map(scene, ppm=6.0, title=f"district: {d}").save(path)
        shown = {k: kinds.get(k, 0) for k in ("building", "hedge", "fence", "wall", "tree", "bush", "car")}
        print(f"{d:<15} streets {dict(types)}  {shown}  {time.perf_counter() - t0:.0f} s  -> {path}")


if __name__ == "__main__":
    main()
