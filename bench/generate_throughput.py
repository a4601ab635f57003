"""Dataset throughput of ``urbangen generate`` (issue 8), read from the manifest's run records.

For each worker count: frames and images per hour, the share of worker time spent
outside Cycles' RGB render calls (target <= 15 %), and worker memory. A memory run
renders many small frames and prints each worker's RSS against frames done, to show
whether memory grows with the number of frames.

    python bench/generate_throughput.py [--config preview] [--frames 2] [--workers 1 2]
                                        [--memory-frames 200] [--out /tmp/ug_gen]
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
from pathlib import Path


def generate(out: Path, spec: str, config: str, frames: int, workers: int, variants: str) -> dict:
    shutil.rmtree(out, ignore_errors=True)
    cmd = [sys.executable, "-m", "generator.cli", "-q", "generate", spec, "--config", config, "--out", str(out),
           "--frames", str(frames), "--workers", str(workers), "--variants", variants]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return json.loads((out / "manifest.json").read_text())["runs"][-1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--spec", default="scenes/default_town.json")
    ap.add_argument("--config", default="preview")
    ap.add_argument("--frames", type=int, default=2)
    ap.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--variants", default="all")
    ap.add_argument("--memory-frames", type=int, default=200)
    ap.add_argument("--out", type=Path, default=Path("/tmp/ug_gen_bench"))
    a = ap.parse_args()
    print(f"{a.spec}, {a.config}, {a.frames} frames x variants={a.variants}")
    print(f"{'workers':>8}{'wall s':>9}{'frames/h':>10}{'images/h':>10}{'outside RGB sampling':>22}"
          f"{'worker setup s':>16}{'worker RSS MB':>15}")
    for w in a.workers:
        r = generate(a.out / f"w{w}", a.spec, a.config, a.frames, w, a.variants)
        print(f"{w:>8}{r['render_wall_s']:>9.1f}{r['frames_per_hour']:>10.1f}{r['images_per_hour']:>10.1f}"
              f"{r['share_outside_rgb_sampling']:>22.1%}{str(r['worker_setup_s']):>16}{str(r['worker_rss_mb']):>15}")
    if a.memory_frames:
        r = generate(a.out / "mem", "scenes/test_town.json", "test", a.memory_frames, 1, "clear")
        rss = dict(r["rss_by_frames_done"])
        marks = sorted(rss)  # sampled after 1, 2, 4, 8 ... frames (generate keeps a bounded sample)
        print(f"memory run: test town, test preset, {a.memory_frames} frames, 1 worker: RSS MB after "
              + ", ".join(f"{n} frames {rss[n]:.0f}" for n in marks))


if __name__ == "__main__":
    main()
