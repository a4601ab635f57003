"""The parent's bookkeeping of ``generate`` at 10k, 100k and 1M planned images (issue 30).

Runs ``generate`` with stand-in tasks (:mod:`generator.jobs.dry`: no Blender, no LiDAR; each task
writes an empty file per item, two local workers) on the test town re-drawn every 100 frames, with
the 12 variants of seed 003 (1M images = 83 334 frames, 834 towns). Per run:

* the parent's time per finished frame: inside the recording (journal line, ledger, counters) and
  the parent's whole CPU time (dispatch, queues, progress) divided by the frames;
* beside it, today's bookkeeping before the journal: ``manifest.json`` listing every finished image,
  rewritten after every frame (measured on a manifest of the same size: the cost of the last frame's
  rewrite; the run's total is the sum over frames, O(n^2));
* the parent's peak memory;
* a resume of the finished plan with the journal as a killed run leaves it (one line per frame, the
  last frame not recorded) -- and of a 1M-frame, one-variant plan (a million journal lines).

    python bench/bookkeeping.py --work /tmp/ug_bookkeeping [--sizes 10000 100000 1000000]
"""

from __future__ import annotations

import argparse
import json
import resource
import shutil
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _spec(work: Path, every: int = 100):
    from generator.spec import load_spec

    doc = json.loads((ROOT / "scenes" / "test_town.json").read_text())
    doc["town"]["redraw_every_frames"] = every
    path = work / "towns.json"
    path.write_text(json.dumps(doc))
    return load_spec(path)


def _instrument():
    """Time spent inside the parent's recording of messages (RunSource.on_message)."""
    from generator.jobs import schedule

    clock = {"s": 0.0, "n": 0}
    original = schedule.RunSource.on_message

    def timed(self, task, msg):
        t = time.perf_counter()
        original(self, task, msg)
        clock["s"] += time.perf_counter() - t
        clock["n"] += msg[0] == "frame"

    schedule.RunSource.on_message = timed
    return clock


def run_once(spec, out: Path, frames: int, combos, workers: int = 2) -> dict:
    from generator.jobs.generate import GenerateOptions, run_generate
    from generator.jobs.plan import make_plan
    from generator.spec.render import load_render_config

    clock = _instrument()
    cpu0 = resource.getrusage(resource.RUSAGE_SELF)
    t0 = time.perf_counter()
    rec = run_generate(spec, load_render_config("test"),
                       GenerateOptions(out, make_plan(frames, combos=combos), workers, stand_in=True))
    wall = time.perf_counter() - t0
    cpu1 = resource.getrusage(resource.RUSAGE_SELF)
    cpu = (cpu1.ru_utime - cpu0.ru_utime) + (cpu1.ru_stime - cpu0.ru_stime)
    return {"wall_s": wall, "cpu_s": cpu, "record_s": clock["s"], "frames": clock["n"], "tasks": rec["tasks"],
            "max_rss_mb": cpu1.ru_maxrss / 1024}


def todays_rewrite(spec, cfg, images: int, frames: int, combos, work: Path, repeats: int = 3) -> float:
    """Seconds of one ``manifest.json`` rewrite as generate did it after every frame before the journal, when
    the manifest lists ``images`` finished images and ``frames`` planned frames (version 1)."""
    from generator.jobs import manifest as mf
    from generator.jobs.images import image_name
    from generator.jobs.plan import make_plan

    plan = make_plan(frames, combos=combos)
    m = mf.new_manifest(spec, cfg, plan, "local")
    m["plan"] = {"frames": list(range(frames)), "combos": [list(c) for c in combos], "sequence": "00",
                 "images": frames * len(combos)}
    names = [image_name(k, t, w) for k in range(frames) for t, w in combos][:images]
    m["finished"] = {"images": names, "lidar": True, "openlabel": False, "stats": False, "stereo": []}
    folder = work / "v1"
    folder.mkdir(parents=True, exist_ok=True)
    times = []
    for _ in range(repeats):
        m["finished"]["images"].append(names[-1])  # one more frame's images, as on_frame did
        t = time.perf_counter()
        mf.save(folder, m)
        times.append(time.perf_counter() - t)
    shutil.rmtree(folder)
    return statistics.median(times)


def killed_journal(out: Path, plan, drop_last: bool = True) -> None:
    """Rewrite ``out``'s journal as a run killed just before its last frame leaves it: ``merged.log`` gone,
    one segment with a line per frame (and the towns' and dataset's lines), the last frame missing."""
    from generator.jobs.journal import Journal

    whole = Journal(out)
    ledger = whole.load()
    whole.remove()
    j = Journal(out)
    last = plan.frames.max()
    for k in plan.frames:
        if not (drop_last and k == last):
            j.record_frame(k, plan.combos)
    for (seq, product), (frames, extra) in ledger.towns.items():
        j.ledger.add_town(seq, product, frames, extra)
        j._append(" ".join([f"town {seq} {product} {frames}", *(f"{a}={b}" for a, b in sorted(extra.items()))]))
    for seq, js in ledger.stereo.items():
        for jj in sorted(js):
            j.record_stereo(seq, jj)
    for product, fp in ledger.dataset.items():
        j.record_dataset(product, fp)
    j.close()


def synthetic_dataset(spec, out: Path, frames: int, combos) -> None:
    """A finished stand-in dataset's journal and manifest without running it (the million-frame case):
    every town's products, stereo pair and dataset product recorded; the frames recorded by the caller."""
    from generator.jobs import manifest as mf
    from generator.jobs.journal import Journal
    from generator.jobs.plan import make_plan
    from generator.jobs.schedule import plan_fingerprint
    from generator.jobs.stereo import stereo_frames
    from generator.jobs.towns import TownPlan
    from generator.spec.render import load_render_config

    plan = make_plan(frames, combos=combos)
    towns = TownPlan(spec, plan)
    out.mkdir(parents=True, exist_ok=True)
    mf.save(out, mf.new_manifest(spec, load_render_config("test"), plan, "local"))
    j = Journal(out)
    from generator.jobs.dry import stand_in_sweeps

    for i in towns.indices:
        seq, fr = towns.sequence(i), towns.frames(i)
        sweeps = stand_in_sweeps(fr)
        j.record_town(seq, "lidar", fr, sweeps=sweeps)
        j.record_town(seq, "openlabel", fr)
        for s in stereo_frames(spec, range(sweeps)):
            j.record_stereo(seq, s)
    fp = plan_fingerprint(plan, None)
    for product in ("label_config", "stats"):
        j.record_dataset(product, fp)
    j.compact()
    for k in plan.frames:
        j.record_frame(k, plan.combos) if k != plan.frames.max() else None
    j.close()


def measure(kind: str, work: Path, n: int) -> dict:
    """One measurement, in this process (the bench runs each in a fresh one: its peak memory is its own)."""
    from generator.jobs.plan import make_plan
    from generator.spec.render import load_render_config
    from generator.weather import combinations

    spec, combos = _spec(work), combinations()
    frames = -(-n // len(combos))
    out = work / f"n{n}"
    if kind == "run":
        shutil.rmtree(out, ignore_errors=True)
        r = run_once(spec, out, frames, combos)
        r["today_rewrite_s"] = todays_rewrite(spec, load_render_config("test"), frames * len(combos), frames, combos,
                                              work)
        return r
    if kind == "resume":  # the finished run of size n, its journal as a run killed before the last frame
        killed_journal(out, make_plan(frames, combos=combos))
        lines = sum(len(p.read_bytes().splitlines()) for p in (out / "journal").glob("*.log"))
        return {**run_once(spec, out, frames, combos), "lines": lines}
    if kind == "resume-million-frames":
        one = work / "million_frames"
        shutil.rmtree(one, ignore_errors=True)
        synthetic_dataset(spec, one, n, [("day", "clear")])
        lines = sum(len(p.read_bytes().splitlines()) for p in (one / "journal").glob("*.log"))
        return {**run_once(spec, one, n, [("day", "clear")]), "lines": lines}
    raise SystemExit(f"unknown measurement {kind}")


def _in_child(kind: str, work: Path, n: int) -> dict:
    import subprocess

    out = subprocess.run([sys.executable, __file__, "--work", str(work), "--measure", kind, str(n)],
                         check=True, capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--work", type=Path, required=True, help="scratch folder for the stand-in datasets")
    ap.add_argument("--sizes", type=int, nargs="+", default=[10_000, 100_000, 1_000_000], help="planned images")
    ap.add_argument("--keep", action="store_true", help="keep the datasets")
    ap.add_argument("--measure", nargs=2, metavar=("KIND", "N"), help=argparse.SUPPRESS)
    a = ap.parse_args()
    a.work.mkdir(parents=True, exist_ok=True)
    if a.measure:
        print(json.dumps(measure(a.measure[0], a.work, int(a.measure[1]))))
        return
    print("stand-in generate, test town re-drawn every 100 frames, 12 variants, 2 local workers; parent figures")
    print(f"{'planned images':>15}{'frames':>8}{'towns':>7}{'tasks':>7}{'wall s':>9}{'record us/frame':>17}"
          f"{'parent CPU us/frame':>21}{'per image':>11}{'today: rewrite ms/frame':>25}{'parent RSS MB':>15}")
    for n in a.sizes:
        frames = -(-n // 12)
        r = _in_child("run", a.work, n)
        print(f"{frames * 12:>15}{frames:>8}{-(-frames // 100):>7}{r['tasks']:>7}{r['wall_s']:>9.1f}"
              f"{1e6 * r['record_s'] / max(r['frames'], 1):>17.1f}{1e6 * r['cpu_s'] / frames:>21.1f}"
              f"{1e6 * r['cpu_s'] / (frames * 12):>11.1f}{1e3 * r['today_rewrite_s']:>25.2f}{r['max_rss_mb']:>15.0f}",
              flush=True)
    print()
    print("resume: the journal as a run killed just before its last frame leaves it (a line per frame, no merged.log)")
    print(f"{'plan':>34}{'journal lines':>15}{'resume wall s':>15}{'parent RSS MB':>15}")
    n = a.sizes[-1]
    r = _in_child("resume", a.work, n)
    print(f"{f'{-(-n // 12)} frames x 12 variants':>34}{r['lines']:>15}{r['wall_s']:>15.2f}{r['max_rss_mb']:>15.0f}",
          flush=True)
    r = _in_child("resume-million-frames", a.work, 1_000_000)
    print(f"{'1000000 frames x 1 variant':>34}{r['lines']:>15}{r['wall_s']:>15.2f}{r['max_rss_mb']:>15.0f}")
    if not a.keep:
        for n in a.sizes:
            shutil.rmtree(a.work / f"n{n}", ignore_errors=True)
        shutil.rmtree(a.work / "million_frames", ignore_errors=True)


if __name__ == "__main__":
    main()
