"""Bench of skies and light (issue 14 items 2, 3): scene luminance per time of day and weather,
and the RGB render cost, of one or more image datasets side by side (e.g. before and after).

For every image (``images/*.exr`` + its metadata JSON) it recovers the scene radiance the
camera saw -- the EXR RGB divided by the camera model's exposure and vignetting when the model
was on, the EXR RGB itself when off -- and prints per dataset and (time of day, weather):

* mean linear luminance (Rec. 709 weights) and the camera's metered (log-average) luminance,
* the ratio of each to the day image of the same frame and weather (night/day, dusk/day),
* the median Cycles RGB pass seconds (``timings_s.rgb_pass``) per render kind.

    python bench/skies.py BEFORE_DIR AFTER_DIR [--frames 2 3] [--sheet OUT.png]

``--sheet`` writes a contact sheet: one row per frame and dataset (captioned with the folder),
one column per (time of day, weather) found in any of them, each image as its camera shows it
(:func:`generator.previews.preview.display_rgb`), blank where a dataset has no such image.

Run both datasets at the same config and frames; the render seconds are only comparable when
both ran on the same machine under the same load.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
from collections import defaultdict
from pathlib import Path

import numpy as np

from generator.imaging.exr import read_exr
from generator.imaging.paths import image_files
from generator.postfx.camera import vignetting_map
from generator.postfx.filters import luminance
from generator.weather import KINDS, TIMES

COLUMN_ORDER = [(t, k) for t in TIMES for k in KINDS]


def scene_radiance(rgb: np.ndarray, meta: dict) -> np.ndarray:
    """(H, W, 3) float32: the radiance in front of the camera (undoing exposure and vignetting)."""
    cam = meta.get("camera_model")
    if not cam:
        return rgb
    h, w = rgb.shape[:2]
    return rgb / (cam["exposure"]["exposure"] * vignetting_map(h, w, cam["params"]["vignetting"]))[..., None]


def measure(folder: Path, frames: set[int] | None) -> dict:
    """{(frame, time, weather): {"mean": float, "metered": float or None, "rgb_s": float}}."""
    out = {}
    for exr in image_files(folder, "*.exr"):
        meta = json.loads(exr.with_suffix(".json").read_text())
        if frames and meta["frame"] not in frames:
            continue
        img = read_exr(exr)
        rad = scene_radiance(img.rgb.astype(np.float32), meta)
        cam = meta.get("camera_model") or {}
        out[(meta["frame"], meta["time_of_day"], meta["weather"]["kind"])] = {
            "mean": float(luminance(rad).mean()),
            "metered": cam.get("exposure", {}).get("metered_luminance"),
            "ev": cam.get("exposure", {}).get("ev"),
            "rgb_s": meta.get("timings_s", {}).get("rgb_pass"),
        }
    return out


def contact_sheet(folders: list[Path], frames: set[int] | None, out: Path, tile_w: int = 320) -> None:
    """Rows: frame x dataset; columns: (time, weather) in table order; each tile as its camera shows it."""
    from PIL import Image, ImageDraw

    from generator.previews.preview import display_rgb

    found = {}
    for i, folder in enumerate(folders):
        for exr in image_files(folder, "*.exr"):
            meta = json.loads(exr.with_suffix(".json").read_text())
            if frames and meta["frame"] not in frames:
                continue
            found[(meta["frame"], i, meta["time_of_day"], meta["weather"]["kind"])] = (exr, meta)
    cols = [c for c in COLUMN_ORDER if any(key[2:] == c for key in found)]
    rows = sorted({(k[0], k[1]) for k in found})
    first = next(iter(found.values()))
    h0, w0 = read_exr(first[0]).rgb.shape[:2]
    tile_h, cap = round(tile_w * h0 / w0), 16
    sheet = Image.new("RGB", (tile_w * len(cols), (tile_h + cap) * len(rows) + cap), (255, 255, 255))
    d = ImageDraw.Draw(sheet)
    for j, (tod, kind) in enumerate(cols):
        d.text((j * tile_w + 4, 2), f"{tod} / {kind}", fill=(0, 0, 0))
    for i, (frame, ds) in enumerate(rows):
        y = cap + i * (tile_h + cap)
        d.text((4, y + 2), f"frame {frame}: {folders[ds]}", fill=(0, 0, 0))
        for j, (tod, kind) in enumerate(cols):
            hit = found.get((frame, ds, tod, kind))
            if hit is None:
                d.text((j * tile_w + tile_w // 2 - 20, y + cap + tile_h // 2), "(none)", fill=(128, 128, 128))
                continue
            img = Image.fromarray(display_rgb(read_exr(hit[0]).rgb, hit[1].get("camera_model")))
            sheet.paste(img.resize((tile_w, tile_h), Image.LANCZOS), (j * tile_w, y + cap))
    out.parent.mkdir(parents=True, exist_ok=True)
    sheet.save(out)


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("datasets", nargs="+", type=Path)
    p.add_argument("--frames", nargs="*", type=int, default=None)
    p.add_argument("--sheet", type=Path, default=None, help="write a before/after contact sheet PNG here")
    a = p.parse_args(argv)
    frames = set(a.frames) if a.frames else None
    if a.sheet:
        contact_sheet(a.datasets, frames, a.sheet)
        print(f"contact sheet: {a.sheet}")
    for folder in a.datasets:
        m = measure(folder, frames)
        print(f"\n== {folder} ({len(m)} images)")
        print(f"{'time':6s} {'weather':9s} {'mean lum':>10s} {'/ day':>9s} {'EV below':>8s} {'metered':>10s} "
              f"{'/ day':>9s} {'cam EV':>7s} {'rgb s':>6s}")
        groups = defaultdict(list)
        for (k, tod, kind), r in m.items():
            day = m.get((k, "day", kind))
            ratio = r["mean"] / day["mean"] if day else float("nan")
            mratio = (r["metered"] / day["metered"]) if day and r["metered"] and day["metered"] else float("nan")
            groups[(tod, kind)].append((r["mean"], ratio, r["metered"] or float("nan"), mratio, r["ev"], r["rgb_s"]))
        order = {"day": 0, "dusk": 1, "night": 2}
        for (tod, kind), rows in sorted(groups.items(), key=lambda x: (order.get(x[0][0], 9), x[0][1])):
            mean, ratio, met, mratio, ev, secs = (
                statistics.fmean(v for v in col if v is not None and not math.isnan(v))
                if any(v is not None and not math.isnan(v) for v in col)
                else float("nan")
                for col in zip(*rows, strict=False)
            )
            below = -math.log2(ratio) if ratio > 0 else float("nan")
            print(f"{tod:6s} {kind:9s} {mean:10.5f} {ratio:9.5f} {below:8.2f} {met:10.5f} {mratio:9.5f} "
                  f"{ev:7.2f} {secs:6.1f}")


if __name__ == "__main__":
    main()
