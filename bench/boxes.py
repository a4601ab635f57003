"""Bench of the detection labels (issue 26): box records, per-image visibility and the KITTI export
beside what ``generate`` spends on the same dataset.

For a dataset made by ``generate`` (e.g. ``--config preview``), in one run:

* rebuilds its scene and world once (``generate`` has them in hand, so this is shown apart);
* times :func:`generator.jobs.box_labels.write_sequence_boxes` with them: box records of every sweep
  and the visibility of every image (seed-003 frames and stereo images), written to a scratch copy;
* times ``export kitti-object`` of the sequence into a scratch folder;
* baselines in the same run: one LiDAR sweep cast again (:class:`generator.lidar.scan.Scanner`), and
  the dataset's own record of ``generate``: its wall time (manifest ``runs``) and per-image render
  times (metadata ``timings_s``).

Prints per image frame: generate's seconds and the labels' seconds and their share (budget 5 %).

    python bench/boxes.py DATASET [--spec scenes/default_town.json]
"""

from __future__ import annotations

import argparse
import json
import shutil
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("dataset", type=Path)
    args = ap.parse_args()
    from generator.jobs.box_labels import write_sequence_boxes
    from generator.jobs.boxes import open_sequence
    from generator.jobs.kitti_export import export_kitti_object
    from generator.lidar.scan import Scanner
    from generator.lidar.sensors import sensor_for_spec
    from generator.spec import parse_spec

    root = args.dataset
    manifest = json.loads((root / "manifest.json").read_text())
    spec = parse_spec(manifest["spec"], str(root / "manifest.json"))
    t = time.perf_counter()
    sw = open_sequence(spec, root, "00")
    rebuild = time.perf_counter() - t
    images = sorted((root / "images").glob("*.json"))
    frames = len({p.name[:6] for p in images}) or 1
    with tempfile.TemporaryDirectory() as tmp:
        copy = Path(tmp) / "ds"
        copy.mkdir()
        for item in ("lidar", "images", "manifest.json"):
            src = root / item
            (shutil.copytree if src.is_dir() else shutil.copy)(src, copy / item)
        t = time.perf_counter()
        _, stats = write_sequence_boxes(spec, copy, scene=sw.scene, world=sw.world)
        boxes_s = time.perf_counter() - t
        t = time.perf_counter()
        kitti = export_kitti_object(copy, Path(tmp) / "kitti")
        export_s = time.perf_counter() - t
    sensor = sensor_for_spec(spec)
    with Scanner(sw.scene, sensor, world=sw.world) as scanner:
        scanner.sweep(sw.rig, 0.0, spec.sensors.lidar.motion_skew)        # warm-up (BVH)
        t = time.perf_counter()
        scanner.sweep(sw.rig, float(sw.seq.times[len(sw.seq.frames) // 2]), spec.sensors.lidar.motion_skew)
        sweep_s = time.perf_counter() - t
    wall = sum(r.get("wall_s", 0.0) for r in manifest.get("runs", []))
    renders = [json.loads(p.read_text()).get("timings_s", {}) for p in images]
    rgb = statistics.median(r.get("rgb_pass", np.nan) for r in renders) if renders else float("nan")
    n_img = stats["images"]
    print(f"dataset {root}: {frames} image frames, {len(sw.seq.frames)} sweeps, {n_img} images with visibility "
          f"({stats['image_boxes']} image boxes), {stats['records']} sweep records; render config "
          f"{manifest['render_config']['name']} {manifest['render_config']['resolution']}")
    print(f"{'':38}{'seconds':>10}{'per frame':>12}")
    rows = [("generate (manifest wall time)", wall), ("  median RGB pass of one image", rgb),
            ("  one LiDAR sweep, cast in this run", sweep_s), ("scene + world rebuilt (generate has them)", rebuild),
            ("box records + visibility", boxes_s), ("  of it: visibility", stats["visibility_s"]),
            ("export kitti-object", export_s)]
    for name, s in rows:
        print(f"{name:38}{s:10.2f}{s / frames:12.3f}")
    labels = boxes_s + export_s
    print(f"labels + export per frame: {labels / frames:.3f} s = {100 * labels / max(wall, 1e-9):.2f} % of generate's "
          f"{wall / frames:.1f} s per frame (budget 5 %); KITTI export of {len(sw.seq.frames)} sweeps "
          f"({kitti['samples']} samples): {export_s:.2f} s")


if __name__ == "__main__":
    main()
