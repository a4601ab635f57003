"""Time the walkers' static obstacles with and without skipping far objects, and check the tiles agree.

    python bench/walk_obstacles.py [SPEC ...] [--rounds 2]

For each town (default: the test, default and kitti_like towns) the scene is built once; then
:func:`generator.traffic.pedestrians.walkways.obstacles_of` (objects wholly beyond the walkways'
reach skipped before their collision bands are made and tiled) and the baseline
:class:`generator.traffic.pedestrians.clear.Obstacles` with the same ``keep`` and no ``near``
(every object tiled, then filtered) run in turn, ``--rounds`` times each, interleaved. Columns:
objects, tiles kept, best seconds of each, their ratio and whether the tiles are byte-identical.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from generator.layout import build_scene  # noqa: E402
from generator.layout.network.draw import make_grid  # noqa: E402
from generator.spec import load_spec  # noqa: E402
from generator.traffic.pedestrians import clear as wc  # noqa: E402
from generator.traffic.pedestrians.lines import street_distance  # noqa: E402
from generator.traffic.pedestrians.walkways import obstacles_of  # noqa: E402

BODY = wc.Body(0.45, 0.45, 1.95)     #: a walker's envelope of the size the simulation makes


def _baseline(grid, scene) -> wc.Obstacles:
    """Every object's bands tiled, then the tiles beyond the walkways' reach dropped (no ``near``)."""
    reach = grid.corridor_half + 2.0
    return wc.Obstacles(scene, grid.curb_h + BODY.height + 0.1, keep=lambda xy: street_distance(grid, xy) < reach)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("specs", nargs="*", type=Path,
                    default=[ROOT / "scenes" / n for n in ("test_town.json", "default_town.json", "kitti_like.json")])
    ap.add_argument("--rounds", type=int, default=2)
    args = ap.parse_args(argv)
    if args.rounds < 1:
        ap.error("--rounds must be at least 1")
    print(f"{'town':<20}{'objects':>8}{'tiles':>8}{'skip s':>9}{'all s':>9}{'ratio':>7}  same tiles")
    for path in args.specs:
        spec = load_spec(path)
        scene, grid = build_scene(spec), make_grid(spec)
        times: dict[str, list[float]] = {"skip": [], "all": []}
        results = {}
        for _ in range(args.rounds):
            for name in ("skip", "all"):
                t0 = time.perf_counter()
                results[name] = obstacles_of(grid, scene, BODY) if name == "skip" else _baseline(grid, scene)
                times[name].append(time.perf_counter() - t0)
        a, b = results["skip"], results["all"]
        same = a.boxes.shape == b.boxes.shape and a.boxes.tobytes() == b.boxes.tobytes() and a.reach == b.reach
        ts, ta = min(times["skip"]), min(times["all"])
        print(f"{path.stem:<20}{len(scene.objects):>8}{len(a.boxes):>8}{ts:>9.2f}{ta:>9.2f}{ta / ts:>7.1f}  {same}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
