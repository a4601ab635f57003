"""Bench of the nuScenes and COCO exports and the processed twin, beside the cost of reading the data.

For a dataset made by ``generate`` (its 41-sweep sequence with a box file), in one run:

* baseline: every scan, its labels and side files read once (what any exporter must at least do), and
  the dataset's own record of ``generate`` (its wall time, manifest ``runs``);
* ``export nuscenes`` (box records from the box file: no rebuild), ``export coco`` and ``process
  --domain-gap seed002`` into scratch folders, each timed whole (command line, in process).

Prints seconds, milliseconds per sweep or image, and each as a multiple of the baseline.

    python bench/exports.py DATASET
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path


def _read_all(root: Path) -> tuple[float, int]:
    from generator.formats import semantickitti as sk
    from generator.formats.point_sidecars import SIDECARS, read_sidecar

    t0 = time.perf_counter()
    n = 0
    for seq_dir in sorted((root / "lidar" / "sequences").glob("[0-9][0-9]")):
        seq = sk.Sequence(root / "lidar", seq_dir.name)
        for j in seq.frames:
            pts, _, _ = seq.read_labelled(j)
            for folder in SIDECARS:
                read_sidecar(seq.dir, folder, j, len(pts))
            n += 1
    return time.perf_counter() - t0, n


def _timed(argv: list[str]) -> float:
    from generator import cli

    t0 = time.perf_counter()
    code = cli.main(argv)
    if code != 0:
        raise SystemExit(f"{' '.join(argv)}: exit {code}")
    return time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("dataset", type=Path)
    args = ap.parse_args()
    root = args.dataset
    import logging

    logging.basicConfig(level=logging.WARNING)
    base, sweeps = _read_all(root)
    images = len(list((root / "images").glob("*.exr"))) + sum(
        len(list(s.glob("passes_[23]/*.exr"))) for s in (root / "lidar" / "sequences").glob("[0-9][0-9]"))
    manifest = json.loads((root / "manifest.json").read_text()) if (root / "manifest.json").is_file() else {}
    gen = sum(float(r.get("seconds", r.get("wall_s", 0)) or 0) for r in manifest.get("runs", []))
    with tempfile.TemporaryDirectory(prefix="bench-exports-") as tmp:
        rows = [("read scans + labels + side files (baseline)", base, sweeps, "sweep")]
        rows.append(("export nuscenes", _timed(["-q", "export", "nuscenes", str(root), f"{tmp}/nus"]), sweeps, "sweep"))
        rows.append(("export coco", _timed(["-q", "export", "coco", str(root), f"{tmp}/coco"]), images, "image"))
        rows.append(("process --domain-gap seed002",
                     _timed(["-q", "process", str(root), f"{tmp}/twin", "--domain-gap", "seed002"]), sweeps, "sweep"))
    print(f"dataset {root}: {sweeps} sweeps, {images} images" + (f"; generate took {gen:.0f} s" if gen else ""))
    print(f"{'step':<46} {'seconds':>8} {'ms/item':>9} {'x baseline':>11}")
    for name, sec, n, unit in rows:
        print(f"{name:<46} {sec:8.2f} {1000 * sec / max(n, 1):7.1f}/{unit[0]} {sec / base:11.1f}")


if __name__ == "__main__":
    main()
