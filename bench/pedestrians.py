"""Time the pedestrian model and print what the walkers did.

    python bench/pedestrians.py [--spec scenes/default_town.json] [--density 5 10 20] [--steps 600]

For each walking density (standing density a quarter of it) the town is built once and
:func:`generator.traffic.pedestrians.simulate.simulate_pedestrians` runs ``--steps`` samples of
``DT_S``. Columns:

* ``walk`` / ``stand`` -- pedestrians placed;
* ``network s`` -- walk network and conflict zones (once per town and body);
* ``sim s`` -- stepping the walkers (including the warm-up before t = 0);
* ``total s`` -- the whole call;
* ``moving`` -- share of walker samples faster than 0.3 m/s; ``crossing`` -- share on a road;
* ``vmax`` -- fastest walker speed seen, m/s.
"""

from __future__ import annotations

import argparse
import dataclasses
import logging
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from generator.layout import build_scene  # noqa: E402
from generator.layout.network.draw import make_grid  # noqa: E402
from generator.layout.placement.prototypes import Library  # noqa: E402
from generator.spec import load_spec  # noqa: E402
from generator.traffic.lanes.signals import Signals  # noqa: E402
from generator.traffic.movers import DT_S  # noqa: E402
from generator.traffic.pedestrians import sim as walk_sim  # noqa: E402
from generator.traffic.pedestrians import simulate as peds  # noqa: E402
from generator.traffic.pedestrians.lines import street_distance  # noqa: E402


class Clock:
    """Seconds spent inside ``walk_sim.simulate`` while installed."""

    def __init__(self):
        self.seconds = 0.0
        self._orig = walk_sim.simulate

    def __enter__(self):
        def timed(*args, **kwargs):
            t = time.perf_counter()
            try:
                return self._orig(*args, **kwargs)
            finally:
                self.seconds += time.perf_counter() - t
        peds.ws.simulate = timed
        return self

    def __exit__(self, *exc):
        peds.ws.simulate = self._orig


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spec", default=str(ROOT / "scenes" / "default_town.json"))
    ap.add_argument("--density", type=float, nargs="+", default=[5.0, 10.0, 20.0])
    ap.add_argument("--steps", type=int, default=600)
    args = ap.parse_args(argv)
    logging.disable(logging.WARNING)
    base = load_spec(args.spec)
    scene, grid = build_scene(base), make_grid(base)
    print(f"spec {args.spec} (seed {base.seed}), {args.steps} steps of {DT_S} s, "
          f"{peds.sidewalk_length(grid):.0f} m of sidewalk")
    print(f"{'density':>8} {'walk':>5} {'stand':>6} {'network s':>10} {'sim s':>6} {'total s':>8} "
          f"{'moving':>7} {'crossing':>9} {'vmax':>5}")
    for d in args.density:
        spec = dataclasses.replace(base, traffic=dataclasses.replace(
            base.traffic, pedestrians_per_100m=d, standing_pedestrians_per_100m=d / 4))
        with Clock() as clock:
            t0 = time.perf_counter()
            movers = peds.simulate_pedestrians(spec, grid, scene, Signals(spec.seed, grid.nodes),
                                               Library(spec.seed), args.steps, DT_S)
            total = time.perf_counter() - t0
        walkers = [m for m in movers if m.attrs["role"] == "walking"]
        xyz = np.stack([m.track.xyz for m in walkers])
        speed = np.linalg.norm(np.diff(xyz[..., :2], axis=1), axis=2) / DT_S
        road = street_distance(grid, xyz[..., :2].reshape(-1, 2)) < grid.road_half
        print(f"{d:>8.1f} {len(walkers):>5} {len(movers) - len(walkers):>6} {total - clock.seconds:>10.2f} "
              f"{clock.seconds:>6.2f} {total:>8.2f} {np.mean(speed > 0.3):>7.2f} {road.mean():>9.3f} "
              f"{speed.max():>5.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
