"""Motion blur of the camera images, two ways on the same frames, printed side by side (issue 12).

* ``none``: the sharp snapshot at the image time (the reference cost).
* ``cycles``: Cycles' own motion blur. The camera and every actor are keyed at the shutter's
  opening, the image instant and its closing (:mod:`generator.blender.motion`); Cycles builds a
  motion BVH and gives each camera sample its own time in the exposure.
* ``vector``: the sharp snapshot plus Cycles' vector pass (screen-space motion to the opening and
  closing poses, from the same keys), then a blur in numpy: every pixel is splatted along its own
  motion path (:func:`post_blur`).

Each mode gets its own Renderer (one Blender scene) and renders the same image times in the
production order (label passes, then the RGB pass); the first image of each mode pays for the
BVH and kernels and is reported apart. PNGs of one frame (full and a 3x crop around the fastest
visible mover) go to ``--out``.

Choice: **Cycles motion blur** (``generator.blender.motion``). It is exact where a post blur
cannot be: occluded background revealed behind a passing car, moving shadows and reflections,
the ego's own motion blurring near and far objects by their real parallax, and the interaction
of both; the vector blur smears a car's colour over a background it never saw behind the car and
leaves its shadow sharp. Its price is the motion BVH and the extra scene evaluations at the
shutter's ends, measured here; the label passes are unaffected (always rendered without blur).
Measured on the default town with that traffic (52 actors, frame 7), preview 640x360, 12 spp, 10 ms shutter, on
2 cores shared with other jobs (wall time swung by +-30 % with their load, so the process's CPU
time is the cost to read): CPU per image none 16.4 s, Cycles blur 16.7 s (1.02x), vector pass +
post blur 18.6 s (1.13x; the vector pass makes Cycles evaluate the motion in the RGB pass as
well, and the numpy blur adds 0.05 s). Masks, instances and depth of the Cycles mode equal the
sharp render's bit for bit; with the vector pass on, Cycles' motion BVH moves a few far depth
values by ~1e-5 m.

    python bench/motion_blur.py [--spec scenes/default_town.json] [--config preview]
                                [--shutter 0.01] [--images 3] [--rounds 2] [--traffic JSON]
                                [--out out/motion_blur]

A spec without a ``traffic`` block gets ``--traffic`` (default: a few dozen vehicles and cyclists).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import logging
import resource
import time
from pathlib import Path

import numpy as np

log = logging.getLogger("bench.motion_blur")
#: Moving traffic for a spec without a ``traffic`` block (the default town's while it was on).
TRAFFIC = ('{"cars_per_km": 12, "trucks_per_km": 1, "buses_per_km": 0.5, "cyclists_per_km": 2, '
           '"motorcyclists_per_km": 1}')


def post_blur(rgb: np.ndarray, vector: np.ndarray) -> np.ndarray:
    """Blur ``rgb`` along Cycles' vector pass by splatting each pixel over its motion in the exposure.

    Parameters
    ----------
    rgb : (H, W, 3) float32
        Sharp linear RGB at the image instant.
    vector : (H, W, 4) float32
        Cycles' vector pass (X, Y, Z, W) in pixels, Blender's y-up image axes: ``(X, Y)`` is the
        position at the shutter's opening minus the position now, ``(Z, W)`` the position now
        minus the one at its closing.

    Returns
    -------
    (H, W, 3) float32
    """
    h, w, _ = rgb.shape
    to_open = np.stack([vector[..., 0], -vector[..., 1]], -1)     # image axes: x right, y down
    to_close = np.stack([-vector[..., 2], vector[..., 3]], -1)
    reach = float(max(np.abs(to_open).max(), np.abs(to_close).max()))
    taps = int(np.clip(2 * np.ceil(reach) + 1, 3, 41))
    v, u = np.mgrid[0:h, 0:w].astype(np.float32)
    acc = np.zeros((3, h * w))
    weight = np.zeros(h * w)
    flat = rgb.reshape(-1, 3).astype(np.float64)
    for s in np.linspace(-1.0, 1.0, taps):
        d = to_open * -s if s < 0 else to_close * s
        tu = np.clip(np.rint(u + d[..., 0]), 0, w - 1).astype(np.int64)
        tv = np.clip(np.rint(v + d[..., 1]), 0, h - 1).astype(np.int64)
        idx = (tv * w + tu).ravel()
        weight += np.bincount(idx, minlength=h * w)
        for c in range(3):
            acc[c] += np.bincount(idx, weights=flat[:, c], minlength=h * w)
    out = flat.copy()
    hit = weight > 0
    out[hit] = (acc[:, hit] / weight[hit]).T
    return out.reshape(h, w, 3).astype(np.float32)


class Clock:
    """Wall and CPU seconds (this process, all its threads: Cycles') per stage.

    On a machine shared with other jobs the wall time swings with their load; the process's CPU
    time is what the work itself costs.
    """

    def __init__(self):
        self.laps: dict[str, tuple[float, float]] = {}
        self._last = self._now()

    @staticmethod
    def _now() -> tuple[float, float]:
        ru = resource.getrusage(resource.RUSAGE_SELF)
        return time.perf_counter(), ru.ru_utime + ru.ru_stime

    def lap(self, name: str) -> None:
        now = self._now()
        self.laps[name] = (now[0] - self._last[0], now[1] - self._last[1])
        self._last = now


def pick_frame(rig, world, k_px: np.ndarray, width: int, height: int, frames: range) -> int:
    """The frame whose camera sees the most fast movers nearby (projected centres inside the image)."""
    best, best_score = frames[0], -1.0
    for k in frames:
        f = rig.frame(k)
        T = f.T_world_camera
        score = 0.0
        for a in world.actors:
            p = (a.track.position(f.t)[0] + [0, 0, 0.8] - T[:3, 3]) @ T[:3, :3]
            if not 3.0 < p[2] < 30.0:
                continue
            u, v = (k_px @ p)[:2] / p[2]
            if 0 <= u < width and 0 <= v < height:
                score += float(a.track.speed(f.t)[0]) / p[2]
        if score > best_score:
            best, best_score = k, score
    return best


def run_mode(mode: str, spec, scene, world, rig, cfg, shutter: float, frame, times, scratch: Path) -> dict:
    """Render ``times`` of ``frame``'s camera in one mode; seconds per stage per image and the first image."""
    from generator.blender import passes
    from generator.blender.renderer import Renderer
    from generator.jobs.exposure import expose
    from generator.spec.render import MotionBlur
    from generator.weather import draw_lighting

    keyed = dataclasses.replace(cfg, motion_blur=MotionBlur(mode != "none", shutter))
    r = Renderer(scene, spec, keyed, scratch / mode, world)
    r.set_conditions(draw_lighting(spec, frame.index, "day"))
    captured, render = {}, passes._render
    if mode == "vector":
        # The keys are set as for Cycles' blur, but the RGB pass is rendered sharp with the vector
        # pass on (Cycles computes it only without motion blur); the real label pass's vectors
        # (exact, one sample at the pixel centre) drive the post blur.
        r.bscene.view_layers[0].use_pass_vector = True

        def capture(scene_, path, kind="labels"):
            chans = render(scene_, path, kind)
            if path.name == "real.exr":
                captured["vector"] = np.stack([chans[f"Vector.{c}"] for c in "XYZW"], -1)
            return chans

        passes._render = capture
    rows, images = [], {}
    try:
        for t in times:
            clock = Clock()
            expose(r, rig, t, frame.T_ego_camera)
            labels = r.render_labels()
            clock.lap("labels")
            if mode == "vector":
                r.cfg = dataclasses.replace(keyed, motion_blur=MotionBlur(False, shutter))
            rgb, _ = r.render_rgb(seed=1)
            clock.lap("rgb")
            r.cfg = keyed
            if mode == "vector":
                rgb = post_blur(rgb, captured["vector"])
                clock.lap("post")
            rows.append(clock.laps)
            images[t] = (rgb, labels)
    finally:
        passes._render = render
    return {"build_s": r.build_seconds, "rows": rows, "images": images}


def _crop(img: np.ndarray, mask: np.ndarray, zoom: int = 3, size=(96, 160)) -> np.ndarray:
    rows, cols = np.nonzero(mask)
    cy, cx = (int(rows.mean()), int(cols.mean())) if len(rows) else (img.shape[0] // 2, img.shape[1] // 2)
    y0 = int(np.clip(cy - size[0] // 2, 0, img.shape[0] - size[0]))
    x0 = int(np.clip(cx - size[1] // 2, 0, img.shape[1] - size[1]))
    return np.repeat(np.repeat(img[y0:y0 + size[0], x0:x0 + size[1]], zoom, 0), zoom, 1)


def write_pngs(out: Path, images: dict, labels, world, t: float, tag: str, gap: int = 6) -> list[Path]:
    """Full images per mode and one strip of 3x crops (in ``images`` order) around the fastest visible mover."""
    from PIL import Image

    from generator.previews.preview import tonemap

    out.mkdir(parents=True, exist_ok=True)
    seen = [a for a in world.actors if (labels.instance == a.instance_id).any()]
    fastest = max(seen, key=lambda a: float(a.track.speed(t)[0]), default=None)
    mask = labels.instance == fastest.instance_id if fastest is not None else np.zeros(labels.instance.shape, bool)
    paths = []
    tiles = {m: tonemap(rgb) for m, rgb in images.items()}
    for m, tile in tiles.items():
        p = out / f"{m}_{tag}.png"
        Image.fromarray(tile).save(p)
        paths.append(p)
    crops = [_crop(tile, mask) for tile in tiles.values()]
    strip = np.full((crops[0].shape[0], sum(c.shape[1] for c in crops) + gap * (len(crops) - 1), 3), 255, np.uint8)
    x = 0
    for c in crops:
        strip[:, x:x + c.shape[1]] = c
        x += c.shape[1] + gap
    p = out / f"crops_{'_'.join(images)}_{tag}.png"
    Image.fromarray(strip).save(p)
    return paths + [p]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--spec", default="scenes/default_town.json")
    ap.add_argument("--config", default="preview")
    ap.add_argument("--shutter", type=float, default=None, help="seconds (default: the config's)")
    ap.add_argument("--images", type=int, default=3, help="image times per mode and round, 0.1 s apart")
    ap.add_argument("--rounds", type=int, default=2, help="rounds over the modes (interleaved against drift)")
    ap.add_argument("--look-shutter", type=float, default=1 / 30, help="a longer exposure for the look PNGs (0: none)")
    ap.add_argument("--frames", type=int, default=12, help="candidate frames to pick the busiest view from")
    ap.add_argument("--traffic", default=TRAFFIC, help="JSON traffic block for a spec without one ('' to keep it)")
    ap.add_argument("--out", default="out/motion_blur")
    a = ap.parse_args()
    logging.basicConfig(level=logging.WARNING)

    from generator.jobs.drive import plan_drive
    from generator.layout.assemble import build_scene
    from generator.spec.load import parse_spec
    from generator.spec.render import load_render_config
    from generator.spec.validate import read_document

    doc = read_document(a.spec)
    if a.traffic and "traffic" not in doc:
        doc["traffic"] = json.loads(a.traffic)
    spec, cfg = parse_spec(doc, a.spec), load_render_config(a.config)
    shutter = a.shutter if a.shutter is not None else cfg.motion_blur.shutter_s
    scene = build_scene(spec)
    drive = plan_drive(spec, scene, list(range(a.frames)))
    world, rig = drive.world, drive.rig
    k = pick_frame(rig, world, rig.K(cfg.width, cfg.height), cfg.width, cfg.height, range(1, a.frames))
    frame = rig.frame(k)
    times = [round(frame.t + 0.1 * i, 9) for i in range(a.images)]
    out = Path(a.out)
    modes = ("none", "cycles", "vector")
    runs = {m: [] for m in modes}
    for _ in range(a.rounds):
        for m in modes:
            runs[m].append(run_mode(m, spec, scene, world, rig, cfg, shutter, frame, times, out / "scratch"))

    print(f"{spec.name}: {len(world.actors)} actors, frame {k} at t = {frame.t:.2f} s; {cfg.name} "
          f"{cfg.width}x{cfg.height}, {cfg.samples} spp, shutter {shutter * 1000:.1f} ms; {a.rounds} rounds x "
          f"{len(times)} images per mode (the first of a round pays the BVH and kernels: '1st img')")
    print(f"{'mode':<8}{'build s':>9}{'1st img s':>11}{'labels s':>10}{'RGB s':>9}{'post s':>8}{'image s':>9}"
          f"{'min s':>8}{'image CPU s':>13}{'CPU vs none':>13}")
    base = None
    for m in modes:
        steady = [r for run in runs[m] for r in (run["rows"][1:] or run["rows"])]
        wall = {key: float(np.mean([r.get(key, (0.0, 0.0))[0] for r in steady])) for key in ("labels", "rgb", "post")}
        total = [sum(v[0] for v in r.values()) for r in steady]
        cpu = float(np.mean([sum(v[1] for v in r.values()) for r in steady]))
        base = base or cpu
        first = np.mean([sum(v[0] for v in run["rows"][0].values()) for run in runs[m]])
        build = np.mean([run["build_s"] for run in runs[m]])
        print(f"{m:<8}{build:>9.2f}{first:>11.2f}{wall['labels']:>10.2f}{wall['rgb']:>9.2f}{wall['post']:>8.2f}"
              f"{np.mean(total):>9.2f}{min(total):>8.2f}{cpu:>13.2f}{cpu / base:>12.2f}x")
    sharp_rgb, sharp = runs["none"][0]["images"][times[0]]
    for m in ("cycles", "vector"):
        rgb, lab = runs[m][0]["images"][times[0]]
        masks = all(np.array_equal(getattr(lab, n), getattr(sharp, n)) for n in ("class_id", "instance", "real_class",
                                                                                "real_instance"))
        fin = np.isfinite(sharp.depth)
        ddepth = (
            float(np.abs(lab.depth[fin] - sharp.depth[fin]).max())
            if np.array_equal(fin, np.isfinite(lab.depth))
            else np.inf
        )
        print(f"{m}: masks and instances identical to the sharp render: {masks}; max |depth - sharp| {ddepth:.2g} m; "
              f"mean |RGB - sharp| {np.abs(rgb - sharp_rgb).mean():.4f}")
    images = {m: runs[m][0]["images"][times[0]][0] for m in modes}
    paths = write_pngs(out, images, sharp, world, times[0], f"{shutter * 1000:.0f}ms")
    if a.look_shutter:
        look = {"none": images["none"]}
        for m in ("cycles", "vector"):
            look[m] = run_mode(m, spec, scene, world, rig, cfg, a.look_shutter, frame, times[:1],
                               out / "scratch")["images"][times[0]][0]
        paths += write_pngs(out, look, sharp, world, times[0], f"{a.look_shutter * 1000:.0f}ms")
    for p in paths:
        print("wrote", p)


if __name__ == "__main__":
    main()
