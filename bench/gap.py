"""``urbangen gap`` on two sequences: its time beside reading the same scans alone (the baseline).

Usage::

    python bench/gap.py SYNTH REAL [--threads N]

SYNTH and REAL are SemanticKITTI-layout folders (e.g. two 100-sweep ``urbangen lidar`` outputs, raw and
``--domain-gap seed002``). Prints, for the two datasets together:

* reading every scan and its labels (the baseline: what any tool must do),
* the ring fit alone (:mod:`generator.gap.rings`),
* the whole measurement (:func:`generator.gap.measure.measure`, on ``--threads`` threads),
* the whole command (measurement, report, 10 charts), as ``urbangen gap`` runs it.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("datasets", nargs=2)
    ap.add_argument("--threads", type=int, default=os.cpu_count())
    args = ap.parse_args()

    from generator.cli import main as cli
    from generator.gap.measure import measure, objects_mode
    from generator.gap.rings import RingModel
    from generator.gap.sources import open_source
    from generator.lidar.sensors import load_preset

    sensor = load_preset("hdl64e")
    sources = [open_source(p, role, 1) for p, role in zip(args.datasets, ("SYNTH", "REAL"), strict=True)]
    scans = sum(s.n_scans for s in sources)
    points = 0
    t0 = time.perf_counter()
    for s in sources:
        for scan in s.scans():
            points += len(scan.xyz)
    t_read = time.perf_counter() - t0

    model = RingModel(sensor)
    t0 = time.perf_counter()
    for s in sources:
        for scan in s.scans():
            model.fit(scan.xyz)
    t_fit = time.perf_counter() - t0

    mode = objects_mode("auto", sources)
    t0 = time.perf_counter()
    for k, s in enumerate(sources):
        measure(f"d{k}", s, sensor, mode, args.threads)
    t_measure = time.perf_counter() - t0

    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        code = cli(["-q", "gap", *args.datasets, "--out", tmp])
        t_cmd = time.perf_counter() - t0
    assert code == 0, code

    print(f"{scans} scans, {points / scans:.0f} points per scan, objects from {mode}, {args.threads} threads")
    print(f"{'step':<44} {'seconds':>8} {'x read':>7} {'scans/s':>8}")
    for name, t in (("read scans + labels (baseline)", t_read), ("read + ring fit (1 thread)", t_read + t_fit),
                    ("measure (read, fit, histograms, objects)", t_measure),
                    ("urbangen gap (measure, report, charts)", t_cmd)):
        print(f"{name:<44} {t:8.2f} {t / t_read:7.1f} {scans / t:8.1f}")
    print(f"target: urbangen gap on two 100-sweep sequences under 60 s -> {'met' if t_cmd < 60 else 'NOT met'} "
          f"({t_cmd * 200 / scans:.1f} s scaled to 200 scans)")


if __name__ == "__main__":
    main()
