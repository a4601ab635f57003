"""Bench of the camera model in post (issue 14 item 1): its cost per image beside baselines.

Times the camera model (:func:`generator.postfx.camera.apply_camera`: metering, PSF, CA,
vignetting, exposure, noise) and its response curve to 8 bits at 640x360 and 1920x1080, each
stage on its own and in total, and prints them beside baselines measured in the same run: a
plain copy of the image, the fixed tone map it replaces for the 8-bit images, and fog in post
(:func:`generator.postfx.fog.fog_image`). When a dataset folder is given, the RGB render time
recorded in its metadata (``timings_s.rgb_pass``, median over its images, per resolution;
scaled by pixel count to the other resolution and marked "est." when it has none) gives the
share of the render the model costs (budget: 3 %).

    python bench/camera_model.py [DATASET ...] [--repeat 5]

The image is the dataset's first day image resized (nearest) to each resolution, or a
synthetic street (sky, facades, road, lamps) without one.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np

from generator.imaging.exr import read_exr
from generator.imaging.paths import image_files
from generator.postfx import camera as cm
from generator.postfx.camera_crf import crf_8bit
from generator.postfx.fog import fog_image
from generator.previews.preview import tonemap
from generator.rng import stream

RESOLUTIONS = ((640, 360), (1920, 1080))


def timed(fn, repeat: int) -> float:
    """Median wall time (s) of ``fn()`` over ``repeat`` runs (after one warm-up)."""
    fn()
    ts = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t)
    return statistics.median(ts)


def synthetic(h: int, w: int) -> tuple[np.ndarray, np.ndarray]:
    """A street-like linear image and its depth: sky, textured facades, road, a row of lamps."""
    rng = np.random.default_rng(0)
    img = np.empty((h, w, 3), np.float32)
    img[: h // 3] = (0.9, 1.1, 1.5)
    img[h // 3 :] = rng.uniform(0.05, 0.4, (h - h // 3, w, 1)) * np.array([1.0, 0.95, 0.9], np.float32)
    img[h // 3 - 8 : h // 3 - 4, ::64] = 40.0
    depth = np.where(np.arange(h)[:, None] < h // 3, np.inf, 5.0 + np.arange(w)[None, :] / 20.0).astype(np.float32)
    return img, np.broadcast_to(depth, (h, w)).copy()


def resize(a: np.ndarray, h: int, w: int) -> np.ndarray:
    ys = (np.arange(h) * a.shape[0] // h).astype(np.intp)
    xs = (np.arange(w) * a.shape[1] // w).astype(np.intp)
    return np.ascontiguousarray(a[ys][:, xs])


def dataset_info(roots: list[Path]) -> tuple[tuple[np.ndarray, np.ndarray] | None, dict[tuple[int, int], float]]:
    """The first day image (rgb, depth) of the datasets and the median rgb_pass per resolution."""
    image, passes = None, {}
    for root in roots:
        for js in image_files(root, "*.json"):
            rec = json.loads(js.read_text())
            res = tuple(rec.get("render", {}).get("resolution", ()))
            secs = (rec.get("timings_s") or {}).get("rgb_pass")
            if secs is not None and len(res) == 2:
                passes.setdefault(res, []).append(float(secs))
            if image is None and rec.get("time_of_day") == "day":
                im = read_exr(js.parent / rec["files"]["exr"])
                image = (im.rgb.astype(np.float32), im.depth)
    return image, {r: statistics.median(v) for r, v in passes.items()}


def render_time(passes: dict, w: int, h: int) -> tuple[float | None, str]:
    if (w, h) in passes:
        return passes[(w, h)], f"{w}x{h} metadata"
    if passes:
        (rw, rh), s = max(passes.items(), key=lambda kv: kv[0][0] * kv[0][1])
        return s * (w * h) / (rw * rh), f"est. from {rw}x{rh}"
    return None, "no dataset"


def bench_resolution(rgb: np.ndarray, depth: np.ndarray, render: tuple[float | None, str], repeat: int) -> None:
    """Print the table of one resolution."""
    h, w = depth.shape
    p = cm.draw_params(stream(0, "frame", 0, "camera_model", "day", "clear"), "day")
    expo = cm.meter(rgb, p)
    out, rec = cm.apply_camera(rgb, p, np.random.default_rng(0))
    vig = np.float32(expo["exposure"]) * cm.vignetting_map(h, w, p.vignetting)
    rows = [
        ("baseline: copy", timed(lambda: rgb.copy(), repeat)),
        ("baseline: tonemap (8-bit, model off)", timed(lambda: tonemap(rgb), repeat)),
        ("baseline: fog post", timed(lambda: fog_image(rgb, depth, 150.0, "day"), repeat)),
        ("  meter", timed(lambda: cm.meter(rgb, p), repeat)),
        ("  psf", timed(lambda: cm.psf(rgb, p.psf_share), repeat)),
        ("  chromatic aberration", timed(lambda: cm.chromatic_aberration(rgb, p.ca_scale), repeat)),
        ("  vignetting x exposure", timed(lambda: rgb * (np.float32(expo["exposure"])
                                                      * cm.vignetting_map(h, w, p.vignetting))[..., None], repeat)),
        ("  noise", timed(lambda: cm.sensor_noise(rgb * vig[..., None], expo["gain"], p.full_well_e, p.read_noise_e,
                                                   np.random.default_rng(0)), repeat)),
        ("  crf to 8-bit", timed(lambda: crf_8bit(out, rec["crf"]), repeat)),
    ]
    model = timed(lambda: crf_8bit(cm.apply_camera(rgb, p, np.random.default_rng(0))[0], rec["crf"]), repeat)
    rows.append(("camera model total (apply_camera + crf)", model))
    secs, how = render
    print(f"\n{w}x{h}   RGB render: {f'{secs:.1f} s ({how})' if secs else how}")
    print(f"{'stage':42s} {'ms':>9s} {'% of render':>12s}")
    for name, s in rows:
        share = f"{100 * s / secs:11.2f}%" if secs else f"{'-':>12s}"
        print(f"{name:42s} {1000 * s:9.1f} {share}")
    if secs:
        extra = model - rows[1][1]
        print(f"{'model minus the tonemap it replaces':42s} {1000 * extra:9.1f} {100 * extra / secs:11.2f}%")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("datasets", nargs="*", type=Path, help="dataset folders with images/*.json (rgb_pass timings)")
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args(argv)
    image, passes = dataset_info(args.datasets)
    print(f"source: {'dataset day image' if image else 'synthetic street'}; repeat {args.repeat} (median)")
    for w, h in RESOLUTIONS:
        rgb, depth = (resize(image[0], h, w), resize(image[1], h, w)) if image else synthetic(h, w)
        bench_resolution(rgb, depth, render_time(passes, w, h), args.repeat)
    return 0


if __name__ == "__main__":
    sys.exit(main())
