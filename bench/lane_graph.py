"""What one-way streets cost the lane graph: LaneGraph build time, plain town vs the same town with
one-way and shared streets, side by side in one run (the baseline measured here, not remembered).

Usage::

    python bench/lane_graph.py [--repeat 3]

Prints, per town size and lanes per direction, the median build seconds of both towns, their edge
and conflict-key counts, and the ratio. The one-way graph rebuilds its connectors and measures a
larger conflict table (``generator/traffic/one_way.py``); the table is cached per key set, so the
cache is cleared before every build to time the cold case a fresh process pays.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from generator.layout.network.draw import make_grid
from generator.spec import parse_spec
from generator.traffic.lanes.conflicts import conflict_table
from generator.traffic.lanes.graph import LaneGraph


def _spec(types: dict, blocks: int, lanes: int):
    return parse_spec({"name": "bench", "seed": 5, "town": {"blocks_x": blocks, "blocks_y": blocks,
                                                              "lanes_per_direction": lanes},
                       "streets": {"types": types}}, "bench.json")


def _time(grid, repeat: int) -> tuple[float, LaneGraph]:
    out, graph = [], None
    for _ in range(repeat):
        conflict_table.cache_clear()
        t = time.perf_counter()
        graph = LaneGraph(grid)
        out.append(time.perf_counter() - t)
    return float(np.median(out)), graph


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    print(f"{'town':>10} {'lanes':>5} | {'plain s':>8} {'edges':>6} {'keys':>5} | {'one-way+shared s':>16} "
          f"{'edges':>6} {'keys':>5} {'one-way segs':>12} | ratio")
    for blocks in (3, 5):
        for lanes in (1, 2):
            base = make_grid(_spec({"plain": 1}, blocks, lanes))
            mixed = make_grid(_spec({"plain": 1, "one_way": 3, "shared": 1}, blocks, lanes))
            tb, gb = _time(base, args.repeat)
            tm, gm = _time(mixed, args.repeat)
            n_ow = sum(1 for s in mixed.sections if s.one_way)
            print(f"{blocks}x{blocks:<8} {lanes:>5} | {tb:8.2f} {len(gb.edges):6d} {len(gb.conflict):5d} | "
                  f"{tm:16.2f} {len(gm.edges):6d} {len(gm.conflict):5d} {n_ow:12d} | {tm / tb:5.2f}")


if __name__ == "__main__":
    main()
