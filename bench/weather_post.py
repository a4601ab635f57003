"""Bench and contact sheet of the post-processed weather (fog, rain) of seed 003 / issue 4.

Times fog and rain at 640x360 and 1920x1080 and prints each beside baselines measured or
recorded in the same run: the RGB render time of a dataset's metadata (``timings_s.rgb_pass``,
when a dataset folder is given; scaled by pixel count for the other resolution and marked
"est.") and reading the image's EXR (``read_exr``) at that resolution.

    python bench/weather_post.py [DATASET] [--sheet sheet.png] [--repeat 5]

Without a dataset, or for night when the dataset has no night image, a synthetic street
(analytic ray cast: road, facades with windows, lamp posts; lamps and lit windows at night)
stands in. ``--sheet`` writes one image under clear / fog (2 visibilities) / rain (2 rates) /
rain+fog, one row per source and time of day.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from generator.imaging.exr import LabelledImage, read_exr, write_exr
from generator.imaging.paths import image_files
from generator.postfx.fog import fog_image
from generator.postfx.rain import rain_image
from generator.previews.preview import tonemap
from generator.rng import stream

# -- synthetic street -------------------------------------------------------------------
# Ray-cast analytically in the optical camera frame (x right, y down, z forward; camera 1.5 m
# above a flat road, level): road with a dashed centre line, sidewalks, facades with windows,
# lamp posts with lamp heads over the road, sky. By day sun-and-sky shading; by night an
# ambient floor, lamps (emitters) lighting road and facades with 1/r^2, and lit windows.

CAM_H = 1.5
FACADE_X = 9.0
SIDEWALK_X = 6.5
POLE_X, ARM_X, LAMP_H = 6.2, 4.8, 6.8
LAMP_Z = np.arange(8.0, 200.0, 24.0)
LAMP_RGB = np.array([1.0, 0.78, 0.5], np.float32)
LAMP_RADIANCE = 40.0


def street(h: int, w: int, time_of_day: str, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """(rgb (H, W, 3) float32 linear, depth (H, W) float32 metres along the ray, inf = sky)."""
    rng = np.random.default_rng(seed)
    f, cx, cy = w / 2.0, w / 2.0, h * 0.46
    u, v = np.meshgrid(np.arange(w, dtype=np.float32) + 0.5, np.arange(h, dtype=np.float32) + 0.5)
    rx, ry = (u - cx) / f, (v - cy) / f
    norm = np.sqrt(rx * rx + ry * ry + 1.0)
    night = time_of_day == "night"

    # Sky.
    elev = np.clip(-ry, 0, 1)[..., None]
    sky_day = np.array([0.75, 0.9, 1.15], np.float32) * (1 - elev) + np.array([0.35, 0.5, 0.85], np.float32) * elev
    rgb = np.broadcast_to(np.array([0.004, 0.005, 0.009], np.float32) if night else sky_day, (h, w, 3)).copy()
    depth = np.full((h, w), np.inf, np.float32)
    z = np.full((h, w), np.inf, np.float32)  # forward distance of the nearest hit

    # Ground (road, marking, sidewalk), up to 400 m.
    with np.errstate(divide="ignore"):
        tg = np.where(ry > 0, CAM_H / np.maximum(ry, 1e-9), np.inf)
    ground = tg < 400
    gx, gz = rx * tg, tg
    alb = np.where(np.abs(gx) < SIDEWALK_X, 0.09, 0.3)
    alb = np.where((np.abs(gx) < 0.12) & (np.mod(np.minimum(gz, 1e4), 6.0) < 3.0), 0.65, alb)
    z = np.where(ground, tg, z)

    # Facades x = +-FACADE_X in blocks of 20 m with 4 m gaps and random heights.
    heights = rng.uniform(8, 24, 40)
    with np.errstate(divide="ignore", invalid="ignore"):
        tf = np.where(np.abs(rx) > 1e-6, FACADE_X / np.abs(rx), np.inf)
    fz, fh = tf, CAM_H - tf * ry
    block = np.clip((fz // 24).astype(np.int64), 0, 39)
    side = (rx > 0).astype(np.int64)
    bh = heights[(block + 17 * side) % 40]
    facade = (fz < 220) & (np.mod(fz, 24.0) < 20.0) & (fh > 0) & (fh < bh) & (fz < z)
    win = ((np.mod(fz, 3.0) > 0.8) & (np.mod(fz, 3.0) < 2.3) & (np.mod(fh, 3.2) > 1.2) & (np.mod(fh, 3.2) < 2.7)
           & (fh > 2.5))
    win_id = (np.floor(fz / 3.0) * 131 + np.floor(fh / 3.2) * 7 + side * 1009).astype(np.int64)
    z = np.where(facade, fz, z)

    # Shading.
    if not night:
        g_rad = alb * 1.5
        f_alb = np.where(win, 0.12, 0.25 + 0.25 * ((block * 7 + side * 3) % 5) / 4.0)
        f_rad = f_alb * np.where(side == 1, 0.55, 1.3)
    else:
        e_g = np.full((h, w), 0.004, np.float32)
        e_f = np.full((h, w), 0.004, np.float32)
        for lz in LAMP_Z:
            for sx in (-1.0, 1.0):
                lx = sx * ARM_X
                d2 = (gx - lx) ** 2 + (gz - lz) ** 2 + LAMP_H**2
                e_g += LAMP_RADIANCE * 0.15 * LAMP_H / d2**1.5
                fx_ = np.sign(rx) * FACADE_X
                d2f = (fx_ - lx) ** 2 + (fz - lz) ** 2 + (fh - LAMP_H) ** 2
                e_f += LAMP_RADIANCE * 0.15 * np.abs(fx_ - lx) / d2f**1.5
        g_rad = alb * e_g
        lit = (np.abs(np.sin(win_id * 12.9898) * 43758.5453) % 1.0) < 0.35
        level = 0.6 + 2.4 * (np.abs(np.sin(win_id * 78.233) * 12345.678) % 1.0)
        f_rad = 0.3 * e_f
        f_rad = np.where(win & lit, level, np.where(win, 0.1 * e_f, f_rad))
    warm = LAMP_RGB if night else np.array([1.0, 0.97, 0.92], np.float32)
    rgb = np.where(ground[..., None], (g_rad[..., None] * warm), rgb)
    f_col = np.where((win & night)[..., None], LAMP_RGB, warm)
    rgb = np.where(facade[..., None], f_rad[..., None] * f_col, rgb)

    # Lamp posts, arms and heads (a loop over ~16 objects, vectorised over pixels).
    for lz in LAMP_Z:
        for sx in (-1.0, 1.0):
            px, hx = sx * POLE_X, sx * ARM_X
            pole = (np.abs(rx * lz - px) < 0.12) & (CAM_H - ry * lz > 0) & (CAM_H - ry * lz < LAMP_H + 0.1) & (lz < z)
            arm = (np.abs(CAM_H - ry * lz - (LAMP_H + 0.1)) < 0.08) & ((rx * lz - hx) * (rx * lz - px) < 0) & (lz < z)
            head = ((rx * lz - hx) ** 2 + (CAM_H - ry * lz - LAMP_H) ** 2 < 0.09) & (lz < z + 0.5)
            for m, col in ((pole | arm, np.float32(0.03 if night else 0.12) * np.ones(3, np.float32)),
                           (head, LAMP_RADIANCE * LAMP_RGB if night else np.array([0.5, 0.5, 0.5], np.float32))):
                rgb[m] = col
                z = np.where(m, lz, z)
    depth = np.where(np.isfinite(z), z * norm, np.inf).astype(np.float32)
    return rgb.astype(np.float32), depth


# -- sources -----------------------------------------------------------------------------

def dataset_images(root: Path) -> dict[str, tuple[np.ndarray, np.ndarray, float | None]]:
    """First dry or wet image by day and by night: time -> (rgb, depth, rgb_pass seconds or None)."""
    out = {}
    for js in image_files(root, "*.json"):
        rec = json.loads(js.read_text())
        tod = rec.get("time_of_day")
        if tod in out or rec.get("weather", {}).get("kind") not in ("clear", "wet"):
            continue
        im = read_exr(js.parent / rec["files"]["exr"])
        secs = (rec.get("timings_s") or {}).get("rgb_pass")
        out[tod] = (im.rgb, im.depth, None if secs is None else float(secs))
    return out


def resize(rgb: np.ndarray, depth: np.ndarray, h: int, w: int) -> tuple[np.ndarray, np.ndarray]:
    """Nearest-neighbour resize of an image and its depth to (h, w)."""
    ys = (np.arange(h) * rgb.shape[0] // h).astype(np.intp)
    xs = (np.arange(w) * rgb.shape[1] // w).astype(np.intp)
    return np.ascontiguousarray(rgb[ys][:, xs]), np.ascontiguousarray(depth[ys][:, xs])


# -- weather variants (fog first, then rain: drops are nearer than the fog) ----------------

def variant(rgb, depth, tod: str, visibility: float | None, rate: float | None, seed: int = 0) -> np.ndarray:
    out = rgb
    if visibility:
        out = fog_image(out, depth, visibility, tod)[0]
    if rate:
        kind = "rain_fog" if visibility else "rain"
        out = rain_image(out, depth, rate, stream(seed, "frame", 0, "rain", tod, kind), tod)[0]
    return out


COLUMNS = [("clear", None, None), ("fog V=150 m", 150.0, None), ("fog V=40 m", 40.0, None),
           ("rain 4 mm/h", None, 4.0), ("rain 35 mm/h", None, 35.0), ("rain 15 mm/h + fog V=80 m", 80.0, 15.0)]


def sheet(rows: list[tuple[str, np.ndarray, np.ndarray, str]], path: Path) -> None:
    """One row per (label, rgb, depth, time of day), one column per weather variant."""
    tiles = []
    for label, rgb, depth, tod in rows:
        cells = []
        for name, vis, rate in COLUMNS:
            img = Image.fromarray(tonemap(variant(rgb, depth, tod, vis, rate)))
            d = ImageDraw.Draw(img)
            d.rectangle([0, 0, img.width, 16], fill=(0, 0, 0))
            d.text((4, 2), f"{label} | {name}", fill=(255, 255, 255))
            cells.append(np.asarray(img))
        tiles.append(np.concatenate([np.pad(c, ((2, 2), (2, 2), (0, 0)), constant_values=255) for c in cells], 1))
    Image.fromarray(np.concatenate(tiles, 0)).save(path)


# -- timing --------------------------------------------------------------------------------

def timed(fn, repeat: int) -> float:
    """Median wall time (s) of ``fn()`` over ``repeat`` runs (after one warm-up)."""
    fn()
    ts = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t)
    return statistics.median(ts)


def exr_read_time(rgb, depth, repeat: int) -> float:
    h, w = depth.shape
    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / "b.exr"
        write_exr(p, LabelledImage(rgb, np.zeros((h, w), np.uint8), np.zeros((h, w), np.uint32), depth))
        return timed(lambda: read_exr(p), repeat)


def bench(sources: dict, rgb_pass: dict[str, tuple[float, int]], repeat: int) -> None:
    """Print fog/rain times beside read_exr and the recorded RGB render time (per time of day,
    falling back to the other time of day's render when only one was recorded)."""
    print(f"{'size':<10} {'operation':<32} {'ms':>8} {'read_exr ms':>11} {'x read':>7} {'rgb_pass s':>12} {'share':>7}")
    for h, w in ((360, 640), (1080, 1920)):
        for tod in ("day", "night"):
            rgb, depth = sources[tod](h, w)
            base = exr_read_time(rgb, depth, max(1, repeat // 2))
            ops = [("fog V=60 m", lambda rgb=rgb, depth=depth, tod=tod: fog_image(rgb, depth, 60.0, tod)),
                   ("rain 20 mm/h", lambda rgb=rgb, depth=depth, tod=tod:
                       rain_image(rgb, depth, 20.0, np.random.default_rng(1), tod)),
                   ("rain 40 mm/h", lambda rgb=rgb, depth=depth, tod=tod:
                       rain_image(rgb, depth, 40.0, np.random.default_rng(1), tod)),
                   ("rain 20 mm/h + fog V=60 m", lambda rgb=rgb, depth=depth, tod=tod:
                       variant(rgb, depth, tod, 60.0, 20.0))]
            for name, fn in ops:
                t = timed(fn, repeat)
                ref = rgb_pass.get(tod) or next(iter(rgb_pass.values()), None)
                if ref:
                    secs, px = ref
                    est = secs * (h * w) / px
                    mark = "" if px == h * w else " est."
                    share = f"{100 * t / est:6.2f}%"
                    rp = f"{est:7.1f}{mark:>5}"
                else:
                    share, rp = "n/a", "n/a"
                print(f"{f'{w}x{h}':<10} {tod + ' ' + name:<32} {1000 * t:8.1f} {1000 * base:11.1f} {t / base:7.2f} "
                      f"{rp:>12} {share:>7}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("dataset", nargs="?", type=Path, help="dataset folder with images/*.json (+ EXR)")
    ap.add_argument("--sheet", type=Path, help="write the contact sheet PNG here")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--no-bench", action="store_true", help="only write the sheet")
    a = ap.parse_args(argv)
    real = dataset_images(a.dataset) if a.dataset else {}
    rgb_pass = {t: (v[2], v[0].shape[0] * v[0].shape[1]) for t, v in real.items() if v[2] is not None}
    for t, (secs, px) in rgb_pass.items():
        print(f"baseline: {t} RGB render (timings_s.rgb_pass) {secs:.1f} s at {px:,} pixels")
    sources = {tod: (lambda h, w, tod=tod: resize(*real[tod][:2], h, w)) if tod in real else
               (lambda h, w, tod=tod: street(h, w, tod)) for tod in ("day", "night")}
    print("sources: " + ", ".join(f"{t}={'render' if t in real else 'synthetic street'}" for t in ("day", "night")))
    if a.sheet:
        rows = [(f"render {t}", *real[t][:2], t) for t in ("day", "night") if t in real]
        rows += [(f"synthetic {t}", *street(360, 640, t), t) for t in ("day", "night")]
        sheet(rows, a.sheet)
        print(f"sheet: {a.sheet}")
    if not a.no_bench:
        bench(sources, rgb_pass, a.repeat)
    return 0


if __name__ == "__main__":
    sys.exit(main())
