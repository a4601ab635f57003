"""Where the label passes' time goes, before and after issue 14 item 6, beside the RGB pass.

One process, one town, the same camera poses. Per pose the dry RGB pass is rendered with the
config (once to warm up, then ``--rgb`` times), then for every supersampling factor the label
passes of both versions, interleaved:

* before: the label passes as they were at 2ae07a5 (:func:`legacy_render_labels`, a verbatim
  copy): a 1x "real" render with the proxies hidden, then the label render with the proxies
  shown, at ``k`` times the resolution -- two scene states, so two Cycles syncs and BVH builds;
* after: :func:`generator.blender.passes.render_labels`.

Production renders the RGB pass before the labels of every image, so the scene leaves the RGB
state before each label measurement: a 1-sample RGB render (same resolution, materials and
visibility as the real one, so Cycles has the same re-sync to do when the labels start).

Each label measurement is split into stages from Blender's render-stats callbacks and timers
around the code: ``prepare`` (the render operator until its render_pre handler: depsgraph
evaluation of the state switch), ``sync`` (Cycles object sync), ``update`` (shaders, meshes,
attributes, device copies), ``bvh`` (scene BVH build), ``trace`` (the samples), ``finish``
(end of the render call), ``readback`` (save_render to the scratch EXR and reading it back),
``vote`` (majority vote) and ``rest`` (everything else: Python state switches, decoding,
depth).

What it showed on the default town at preview (2 vCPUs shared with other jobs, so only the
shape is stable, not the seconds): at 3x about half of a label pass is tracing the 9x rays and
about 40 % is the switch out of the RGB state -- writing a view-layer override, even the value it
already holds, makes Cycles re-sync every object and rebuild its BVH (~0.45 s on a quiet
machine); a change of resolution alone costs ~0.1 s and no BVH. Read back and vote are small.

``--rss paper`` instead runs one 3x label pass at the paper preset in a fresh process per
version and prints the process's peak RSS after building the scene and after the pass.

    python bench/label_cost.py [--config preview] [--poses 1] [--reps 2] [--factors 1 3 5]
    python bench/label_cost.py --rss paper
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

STAGES = ("prepare", "sync", "update", "bvh", "trace", "finish", "readback", "vote", "rest")


def _legacy_integers(rgba, what):
    vals = rgba[..., :2]
    ints = np.rint(vals)
    bad = np.abs(vals - ints) > 1e-3
    if bad.any():
        raise RuntimeError(f"{what}: {int(bad.sum())} pixel values are not integers: labels would be blended")
    return ints[..., 0].astype(np.uint8), ints[..., 1].astype(np.uint16)


def _legacy_vote(values, eligible, centre):
    n = values.shape[-1]
    count = np.zeros(values.shape, np.int16)
    for j in range(n):
        count += (values == values[..., j:j + 1]) & eligible[..., j:j + 1]
    score = 2 * count
    score[..., centre] += 1
    score[~eligible] = -1
    return np.argmax(score, axis=-1)


def legacy_majority_labels(class_id, instance, k):
    """The numpy majority vote at 2ae07a5 (verbatim but for the argument checks)."""
    if k == 1:
        return class_id, instance
    from generator.labels.supersample import _blocks

    cls, inst = _blocks(class_id, k), _blocks(instance, k)
    centre = (k * k) // 2
    everywhere = np.ones(cls.shape, bool)
    win = _legacy_vote(cls, everywhere, centre)
    out_cls = np.take_along_axis(cls, win[..., None], -1)[..., 0]
    same_class = cls == out_cls[..., None]
    win_inst = _legacy_vote(inst, same_class, centre)
    out_inst = np.take_along_axis(inst, win_inst[..., None], -1)[..., 0]
    return np.ascontiguousarray(out_cls), np.ascontiguousarray(out_inst)


def legacy_render_labels(scene, bs, k, scratch, supersample=1):
    """The label passes at 2ae07a5 (verbatim but for imports), for the "before" rows."""
    from generator.blender import geometry, passes, session
    from generator.blender.materials import label_material, label_world
    from generator.world import rig

    session.label_state(scene, label_material(), label_world())
    scene.cycles.transparent_max_bounces = 0
    secs = {}
    geometry.set_proxies_visible(bs, False)
    t = time.perf_counter()
    real = passes._render(scene, scratch / "real.exr")
    secs["real_pass"] = time.perf_counter() - t
    geometry.set_proxies_visible(bs, True)
    t = time.perf_counter()
    with session.supersampled(scene, supersample):
        lab = passes._render(scene, scratch / "label.exr")
    fine_class, fine_instance = _legacy_integers(lab["Combined"], "label pass")
    del lab
    class_id, instance = _timed_legacy_vote(fine_class, fine_instance, supersample)
    secs["label_pass"] = time.perf_counter() - t
    geometry.set_proxies_visible(bs, False)
    real_class, real_instance = _legacy_integers(real["Combined"], "real pass")
    h, w = real_class.shape
    z = real["Depth.Z"] if "Depth.Z" in real else real["Z"]
    cos = rig.pixel_rays(k, w, h)[..., 2]
    depth = (z / cos).astype(np.float32)
    depth[z >= passes.SKY_Z] = np.inf
    return passes.LabelPasses(class_id, instance, real_class, real_instance, depth, secs)


def _timed_legacy_vote(*a):
    return legacy_majority_labels(*a)  # replaced by StageClock with a timed wrapper


class StageClock:
    """Accumulates seconds per stage while installed (render handlers and wrapped functions)."""

    def __init__(self):
        from generator.blender import passes
        from generator.blender.bpy_guard import bpy
        from generator.labels import supersample

        self.bpy, self.passes, self.ss = bpy, passes, supersample
        self.acc: dict = defaultdict(float)
        self._events: list = []
        self._orig_render, self._orig_vote = passes._render, supersample.majority_labels
        self._orig_legacy = legacy_majority_labels
        h = bpy.app.handlers
        h.render_pre.append(self._pre)
        h.render_stats.append(self._stat)

        def render(*a, **kw):
            t0 = time.perf_counter()
            self._events = [(t0, "prepare")]
            c0 = sum(passes.CYCLES_SECONDS.values())
            out = self._orig_render(*a, **kw)
            cycles = sum(passes.CYCLES_SECONDS.values()) - c0
            self._close(t0 + cycles)
            self.acc["readback"] += time.perf_counter() - t0 - cycles
            return out

        def timed(fn):
            def vote(*a, **kw):
                t0 = time.perf_counter()
                out = fn(*a, **kw)
                self.acc["vote"] += time.perf_counter() - t0
                return out
            return vote

        passes._render, passes.majority_labels = render, timed(self._orig_vote)
        globals()["_timed_legacy_vote"] = timed(self._orig_legacy)
        tiny = np.zeros((3, 3), np.uint8)
        self._orig_vote(tiny, tiny.astype(np.uint16), 3)  # load the compiled vote before anything is timed

    def _pre(self, *a):
        self._events.append((time.perf_counter(), "sync"))

    def _stat(self, stats, *a):
        s = str(stats)
        cat = ("bvh" if "BVH" in s else "trace" if ("Sample" in s or "Tile" in s) else "finish" if s.endswith("Finished")
               else "sync" if "Synchroniz" in s else "update")
        if self._events and self._events[-1][1] == "trace" and cat == "trace":
            return
        self._events.append((time.perf_counter(), cat))

    def _close(self, t_end: float) -> None:
        ev = self._events + [(t_end, None)]
        for (t0, cat), (t1, _) in zip(ev, ev[1:]):
            self.acc[cat] += t1 - t0
        self._events = []

    def take(self, total: float) -> dict:
        out = {s: self.acc.get(s, 0.0) for s in STAGES[:-1]}
        out["rest"] = total - sum(out.values())
        out["total"] = total
        self.acc.clear()
        return out


def _rss_child(version: str, config: str, spec_path: str) -> None:
    """One 3x label pass at ``config``'s resolution in this process; print peak RSS (MB) as JSON."""
    from generator.blender import passes
    from generator.blender.renderer import Renderer
    from generator.layout.assemble import build_scene
    from generator.spec import load_spec
    from generator.spec.render import load_render_config
    from generator.world.rig import Rig

    spec, cfg = load_spec(spec_path), dataclasses.replace(load_render_config(config), label_supersample=3)
    scene = build_scene(spec)
    r = Renderer(scene, spec, cfg, Path(tempfile.mkdtemp(prefix="ug_rss_")))
    r.place_camera(Rig.from_spec(spec, scene).frame(5).T_world_camera)
    built = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    fn = passes.render_labels if version == "after" else legacy_render_labels
    t = time.perf_counter()
    fn(r.bscene, r.handles, r.k, r.scratch, 3)
    s = time.perf_counter() - t
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(json.dumps({"version": version, "resolution": cfg.resolution, "built_mb": built, "peak_mb": peak, "s": s}))


def _rss(config: str, spec_path: str) -> None:
    print(f"peak RSS of one 3x label pass at {config}, fresh process per version (MB)")
    print(f"{'':<8}{'after build':>13}{'after pass':>12}{'pass adds':>11}{'seconds':>9}")
    for version in ("before", "after"):
        out = subprocess.run([sys.executable, __file__, "--rss-child", version, "--rss", config, "--spec", spec_path],
                             capture_output=True, text=True, check=True).stdout
        d = json.loads(out.strip().splitlines()[-1])
        print(f"{version:<8}{d['built_mb']:>13.0f}{d['peak_mb']:>12.0f}{d['peak_mb'] - d['built_mb']:>11.0f}{d['s']:>9.2f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--spec", default="scenes/default_town.json")
    ap.add_argument("--config", default="preview")
    ap.add_argument("--poses", type=int, default=1)
    ap.add_argument("--first", type=int, default=5)
    ap.add_argument("--reps", type=int, default=2)
    ap.add_argument("--rgb", type=int, default=1, help="timed dry RGB renders per pose (after one warm-up)")
    ap.add_argument("--factors", type=int, nargs="+", default=[1, 3, 5])
    ap.add_argument("--rss", default=None, help="measure peak RSS of one 3x label pass at this preset instead")
    ap.add_argument("--rss-child", default=None, help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.rss_child:
        return _rss_child(a.rss_child, a.rss, a.spec)
    if a.rss:
        return _rss(a.rss, a.spec)

    from generator.blender import passes
    from generator.blender.renderer import Renderer
    from generator.layout.assemble import build_scene
    from generator.spec import load_spec
    from generator.spec.render import load_render_config
    from generator.weather import draw_lighting
    from generator.world.rig import Rig

    spec, cfg = load_spec(a.spec), load_render_config(a.config)
    scene = build_scene(spec)
    rig = Rig.from_spec(spec, scene)
    r = Renderer(scene, spec, cfg, Path(tempfile.mkdtemp(prefix="ug_labelcost_")))
    switch_cfg = dataclasses.replace(cfg, samples=1, denoiser="none", adaptive_threshold=0.0)
    versions = {"before": legacy_render_labels, "after": passes.render_labels}
    clock = StageClock()
    rgb, rows = [], defaultdict(list)
    for i in range(a.poses):
        f = rig.frame(a.first + 7 * i)
        r.place_camera(f.T_world_camera)
        r.set_conditions(draw_lighting(spec, f.index, "day"))
        r.render_rgb(seed=f.index)  # warm-up: BVH and first shader compile, paid once per process
        rgb += [r.render_rgb(seed=f.index)[1] for _ in range(a.rgb)]
        for _ in range(a.reps):
            for k in a.factors:
                for name, fn in versions.items():
                    passes.render_rgb(r.bscene, r.handles, switch_cfg, f.index, r.scratch)  # leave the labels' state
                    clock.take(0.0)
                    t = time.perf_counter()
                    fn(r.bscene, r.handles, r.k, r.scratch, k)
                    rows[(name, k)].append(clock.take(time.perf_counter() - t))
    rgb_s = statistics.median(rgb)
    print(f"{cfg.name} {cfg.width}x{cfg.height}, {cfg.samples} spp; {a.poses} pose(s), medians of {len(rgb)} dry RGB "
          f"renders and {a.reps * a.poses} label passes per row (s); load average {_load()}")
    print(f"{'':<8}{'k':>3}" + "".join(f"{s:>9}" for s in STAGES) + f"{'total':>9}{'% RGB':>8}")
    for (name, k), runs in sorted(rows.items(), key=lambda kv: (kv[0][1], kv[0][0] != "before")):
        med = {s: statistics.median(run[s] for run in runs) for s in (*STAGES, "total")}
        print(f"{name:<8}{k:>3}" + "".join(f"{med[s]:>9.3f}" for s in STAGES) + f"{med['total']:>9.3f}"
              f"{med['total'] / rgb_s:>8.1%}")
    print(f"dry RGB pass: {rgb_s:.2f} s (runs: {', '.join(f'{s:.2f}' for s in rgb)}); stages are medians per stage, "
          "so they need not add up to the median total exactly. The machine's load is shared: compare within a run.")


def _load() -> str:
    try:
        return Path("/proc/loadavg").read_text().split()[0]
    except OSError:
        return "?"


if __name__ == "__main__":
    main()
