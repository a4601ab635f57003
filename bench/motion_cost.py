"""What the motion ground truth costs beside what it comes from, in one run (issue 28's budget: 5 %).

    python bench/motion_cost.py [SPEC] [--config preview] [--sweeps 20] [--rounds 3]

The default town with its traffic, at the render preset ``--config`` (preview: 640x360, labels at 3x):

* **images/ frame** -- frames 0 and 1 rendered as ``generate`` renders them with one variant
  (day clear: the label passes and ONE RGB render; a frame of all 12 variants renders 6 RGB images,
  so this is the cheapest frame there is), beside the optical flow step of those frames (each
  frame's forward or backward flow, its float EXR and KITTI PNGs, its EXR read back);
* **stereo pair** -- the KITTI pairs of sweeps 0 and 10 rendered (both cameras' labels and RGB),
  beside their flows (both cameras) and disparity, written;
* **LiDAR sweep** -- ``--sweeps`` consecutive sweeps of the drive, the scanner's cast (2 threads)
  beside the scene flow of the same sweeps (:class:`generator.motion.scene_flow.SceneFlow`), each
  the best of ``--rounds`` interleaved rounds, wall and CPU seconds; and the whole sequence writer
  per sweep (cast, scan effects, files, bird's-eye PNG) beside the time its scene-flow files take
  in it.

Everything else on the machine shares the two cores: run it through ``heavy``; the shares are of
figures measured side by side in the same process.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from generator.dataset import Dataset  # noqa: E402
from generator.jobs import scan_flow  # noqa: E402
from generator.jobs.drive import plan_drive  # noqa: E402
from generator.jobs.lidar_sequence import SequenceOptions, write_sequence  # noqa: E402
from generator.jobs.motion import write_motion  # noqa: E402
from generator.layout import build_scene  # noqa: E402
from generator.lidar.scan import Scanner  # noqa: E402
from generator.lidar.sensors import sensor_for_spec  # noqa: E402
from generator.motion.scene_flow import SceneFlow  # noqa: E402
from generator.spec import load_spec  # noqa: E402
from generator.spec.render import load_render_config  # noqa: E402
from generator.world.rig import SWEEP_PERIOD_S, Rig  # noqa: E402


def _clock():
    return time.perf_counter(), time.process_time()


def _since(c):
    return time.perf_counter() - c[0], time.process_time() - c[1]


def images(spec, cfg, scene, drive, out: Path) -> dict:
    """Render frames 0, 1 and the pairs of sweeps 0, 10; then their flows and disparity."""
    from generator.blender.renderer import Renderer
    from generator.jobs.stereo import render_pair
    from generator.jobs.towns import local_frame
    from generator.jobs.variants import render_frames

    renderer = Renderer(scene, spec, cfg, out / ".scratch", drive.world)
    frames = [local_frame(drive.rig, k) for k in (0, 1)]
    c = _clock()
    for _ in render_frames(renderer, spec, cfg, frames, out, [("day", "clear")], drive.rig):
        pass
    frame_s = _since(c)[0] / 2
    sensor = sensor_for_spec(spec)
    seq = out / "lidar" / "sequences" / "00"
    c = _clock()
    for j in (0, 10):
        render_pair(renderer, spec, cfg, drive.rig, sensor, j, seq)
    pair_s = _since(c)[0] / 2
    record = write_motion(Dataset(out), drive.world, [0, 1], "00")
    flow_frame = record["images"]["seconds"] / 2
    flow_pair = (record["image_2"]["seconds"] + record["image_3"]["seconds"] + record["disparity"]["seconds"]) / 2
    return {"frame_s": frame_s, "flow_frame_s": flow_frame, "pair_s": pair_s, "flow_pair_s": flow_pair}


def sweeps(spec, scene, drive, n: int, rounds: int) -> dict:
    """Cast vs scene flow per sweep (best of ``rounds``), wall and CPU."""
    sensor, rig, world = sensor_for_spec(spec), drive.rig, drive.world
    times = [Rig.sweep_time(j) for j in range(1, n + 2)]
    best = {"cast": [np.inf] * n, "cast_cpu": [np.inf] * n, "flow": [np.inf] * n, "flow_cpu": [np.inf] * n}
    with Scanner(scene, sensor, world=world) as scanner:
        pts = [scanner.sweep(rig, t, True).points for t in times]  # warm-up and the flow's input
        SceneFlow.for_rig(rig, world.actors, sensor, True, SWEEP_PERIOD_S).sweep(pts[0], pts[1], times[0])
        for _ in range(rounds):
            flows = SceneFlow.for_rig(rig, world.actors, sensor, True, SWEEP_PERIOD_S)
            for i in range(n):
                c = _clock()
                scanner.sweep(rig, times[i], True)
                w, cpu = _since(c)
                best["cast"][i], best["cast_cpu"][i] = min(best["cast"][i], w), min(best["cast_cpu"][i], cpu)
                c = _clock()
                flows.sweep(pts[i], pts[i + 1], times[i])
                w, cpu = _since(c)
                best["flow"][i], best["flow_cpu"][i] = min(best["flow"][i], w), min(best["flow_cpu"][i], cpu)
    return {k: float(np.median(v)) for k, v in best.items()}


def writer(spec, scene, drive, n: int, out: Path) -> dict:
    """The sequence writer per sweep, and the part of it its scene-flow files take (``ScanFlowWriter.add``)."""
    real, spent = scan_flow.ScanFlowWriter.add, []

    def timed(self, j, t, points):
        c = time.perf_counter()
        real(self, j, t, points)
        spent.append(time.perf_counter() - c)

    scan_flow.ScanFlowWriter.add = timed
    try:
        c = _clock()
        write_sequence(scene, spec, out, SequenceOptions(frames=n), world=drive.world, progress=False)
        total = _since(c)[0]
    finally:
        scan_flow.ScanFlowWriter.add = real
    return {"writer": total / n, "scene_flow": sum(spent) / max(n - 1, 1)}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("spec", nargs="?", default=str(ROOT / "scenes" / "default_town.json"))
    p.add_argument("--config", default="preview")
    p.add_argument("--sweeps", type=int, default=20)
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--skip-render", action="store_true", help="LiDAR rows only")
    args = p.parse_args()
    spec, cfg = load_spec(args.spec), load_render_config(args.config)
    scene = build_scene(spec)
    drive = plan_drive(spec, scene, [0, 1])
    with tempfile.TemporaryDirectory(prefix="motion-cost-") as tmp:
        tmp = Path(tmp)
        lidar = sweeps(spec, scene, drive, args.sweeps, args.rounds)
        whole = writer(spec, scene, drive, min(args.sweeps, 10), tmp / "seq")
        img = None if args.skip_render else images(spec, cfg, scene, drive, tmp / "ds")
    rows = []
    if img is not None:
        rows += [(f"images/ frame at {cfg.name} (labels + 1 RGB)", img["frame_s"], "its optical flow",
                  img["flow_frame_s"]),
                 (f"stereo pair at {cfg.name} (2 x labels + RGB)", img["pair_s"], "flows of both cameras + disparity",
                  img["flow_pair_s"])]
    rows += [("LiDAR sweep: cast (wall, 2 threads)", lidar["cast"], "scene flow (wall)", lidar["flow"]),
             ("LiDAR sweep: cast (CPU)", lidar["cast_cpu"], "scene flow (CPU)", lidar["flow_cpu"]),
             ("LiDAR sweep: the whole sequence writer (cast, effects, files, BEV)", whole["writer"],
              "its scene-flow files (flow, flags, write)", whole["scene_flow"])]
    print(f"{spec.name}, {len(drive.world.actors)} actors, config {cfg.name} ({cfg.width}x{cfg.height})\n")
    print("| baseline | s | motion ground truth | s | share |\n|---|---:|---|---:|---:|")
    for base, b, what, m in rows:
        print(f"| {base} | {b:.4f} | {what} | {m:.4f} | {100 * m / b:.1f} % |")


if __name__ == "__main__":
    main()
