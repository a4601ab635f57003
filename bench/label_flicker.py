"""Flicker of thin markings in the label pass, 1x against the majority-vote supersampling.

The camera creeps forward a few centimetres per frame along the default town's first frame.
For each frame the label pass is rendered the production way (``render_labels`` with
supersample 1, 3 and 5) plus a 7x7 reference from which each pixel's marking coverage
(road_marking + crosswalk, fraction of 49 samples) is taken.

Printed per factor, over consecutive frame pairs and pixels near markings:

* spurious flips: the pixel's marking label changes although its reference coverage stayed
  clearly on one side of 1/2 (both <= 0.3 or both >= 0.7, change < 0.15): geometry barely
  moved, the label did -- that is flicker;
* wrong vs coverage: marked with coverage <= 0.3, or unmarked with coverage >= 0.7;
* marking area: mean and relative spread of the marking pixel count over the frames;
* seconds of the label pass (Cycles + vote) beside the dry RGB pass of the same pose.

A PNG strip (crop of distant markings, frames left to right; rows 1x, 3x, reference coverage)
goes to ``--png``.

    python bench/label_flicker.py [--frames 8] [--step-cm 3] --png OUT.png
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np

FACTORS = (1, 3, 5)
REF = 7


def _marking_ids():
    from generator.labels import class_table

    t = class_table()
    return np.array([t.id("road_marking"), t.id("crosswalk")], np.uint8)


def _reference(r, marks) -> tuple[np.ndarray, np.ndarray]:
    """(H, W) float marking coverage and (H, W) bool centre-sample marking, from a 7x render."""
    from generator.blender import geometry, passes, session
    from generator.blender.materials import label_material
    from generator.labels.supersample import _blocks

    session.label_state(r.bscene, label_material())
    geometry.set_proxies_visible(r.handles, True)
    with session.supersampled(r.bscene, REF):
        fine = passes._render(r.bscene, r.scratch / "ref.exr")
    geometry.set_proxies_visible(r.handles, False)
    cls, _ = passes.label_samples(fine, "reference pass")
    b = np.isin(_blocks(cls, REF), marks)
    return b.mean(-1), b[..., (REF * REF) // 2]


def _crop_box(heat: np.ndarray, h: int = 40, w: int = 80) -> tuple[slice, slice]:
    """The ``h`` x ``w`` window holding the most 1x spurious flips (summed over the frames)."""
    c = np.cumsum(np.cumsum(np.pad(heat.astype(float), ((1, 0), (1, 0))), 0), 1)
    win = c[h:, w:] - c[:-h, w:] - c[h:, :-w] + c[:-h, :-w]
    y0, x0 = np.unravel_index(np.argmax(win), win.shape)
    return slice(y0, y0 + h), slice(x0, x0 + w)


def _strip(path: Path, labels: dict, flips: dict, cov: list, box, n: int) -> None:
    """Rows 1x, 3x (marking white, flips since the previous frame red), coverage; frames left to right."""
    from PIL import Image, ImageDraw

    rows = []
    for k in (1, 3):
        row = []
        for t in range(n):
            tile = np.where(labels[k][t][box], 235, 45).astype(np.uint8)[..., None].repeat(3, -1)
            if t:
                tile[flips[k][t - 1][box]] = (230, 30, 30)
            row.append(tile)
        rows.append(row)
    rows.append([(np.clip(c[box], 0, 1) * 255).astype(np.uint8)[..., None].repeat(3, -1) for c in cov[:n]])
    pad = ((2, 2), (2, 2), (0, 0))
    tiles = [np.concatenate([np.pad(t, pad, constant_values=128) for t in row], 1) for row in rows]
    img = np.kron(np.concatenate(tiles, 0), np.ones((5, 5, 1), np.uint8))
    canvas = Image.fromarray(img)
    d = ImageDraw.Draw(canvas)
    th = (box[0].stop - box[0].start + 4) * 5
    for i, name in enumerate(("1x (pixel centre); red: spurious flip", "3x majority; red: spurious flip",
                              "marking coverage (7x7 reference)")):
        d.text((8, 6 + i * th), name, fill=(60, 200, 255))
    path.parent.mkdir(parents=True, exist_ok=True)
    canvas.save(path)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--spec", default="scenes/default_town.json")
    ap.add_argument("--config", default="preview")
    ap.add_argument("--frame", type=int, default=5)
    ap.add_argument("--frames", type=int, default=8)
    ap.add_argument("--step-cm", type=float, default=3.0)
    ap.add_argument("--png", required=True, help="the strip PNG to write")
    a = ap.parse_args()

    from generator.blender import passes
    from generator.blender.renderer import Renderer
    from generator.layout.assemble import build_scene
    from generator.spec import load_spec
    from generator.spec.render import load_render_config
    from generator.weather import draw_lighting
    from generator.world.rig import Rig

    spec, cfg = load_spec(a.spec), load_render_config(a.config)
    scene = build_scene(spec)
    r = Renderer(scene, spec, cfg, Path(tempfile.mkdtemp(prefix="ug_flicker_")))
    marks = _marking_ids()
    T0 = Rig.from_spec(spec, scene).frame(a.frame).T_world_camera
    r.set_conditions(draw_lighting(spec, a.frame, "day"))
    labels = {k: [] for k in FACTORS}
    secs = {k: [] for k in FACTORS}
    cov, centre_ok = [], []
    r.place_camera(T0)
    rgb_s = r.render_rgb(seed=0)[1]
    for i in range(a.frames):
        T = T0.copy()
        T[:3, 3] += T0[:3, 2] * (a.step_cm / 100 * i)  # forward along the optical axis
        r.place_camera(T)
        for k in FACTORS:
            lab = passes.render_labels(r.bscene, r.handles, r.k, r.scratch, k)
            secs[k].append(lab.seconds["label_pass"])
            labels[k].append(np.isin(lab.class_id, marks))
        c, centre = _reference(r, marks)
        cov.append(c)
        centre_ok.append(float((centre == labels[1][-1]).mean()))

    print(f"{cfg.name} {cfg.width}x{cfg.height}, {a.frames} frames, camera +{a.step_cm:g} cm/frame; "
          f"1x pass == centre samples of the 7x7 reference on {min(centre_ok):.4%} of pixels")
    print(
        f"{'factor':>7}{'spurious flips':>16}{'of pixels':>11}{'wrong vs cov':>14}{'area mean':>11}{'area spread':>13}"
        f"{'label pass s':>14}{'vs RGB':>9}"
    )
    flip_maps: dict = {}
    for k in FACTORS:
        flips = stable_n = wrong = near_n = 0
        flip_maps[k] = []
        for t in range(a.frames - 1):
            c0, c1, m0, m1 = cov[t], cov[t + 1], labels[k][t], labels[k][t + 1]
            near = (c0 > 0) | (c1 > 0) | m0 | m1
            stable = near & (((c0 <= 0.3) & (c1 <= 0.3)) | ((c0 >= 0.7) & (c1 >= 0.7))) & (np.abs(c1 - c0) < 0.15)
            flip_maps[k].append(stable & (m0 != m1))
            flips += int(flip_maps[k][-1].sum())
            stable_n += int(stable.sum())
        for t in range(a.frames):
            c, m = cov[t], labels[k][t]
            wrong += int(((m & (c <= 0.3)) | (~m & (c >= 0.7))).sum())
            near_n += int(((c > 0) | m).sum())
        area = np.array([m.sum() for m in labels[k]], float)
        ls = float(np.median(secs[k]))
        print(f"{k:>6}x{flips:>16}{flips / max(stable_n, 1):>11.3%}{wrong / max(near_n, 1):>14.3%}{area.mean():>11.0f}"
              f"{area.std() / area.mean():>13.2%}{ls:>14.3f}{ls / rgb_s:>9.1%}")
    print(f"dry RGB pass of the first pose: {rgb_s:.2f} s; 'of pixels' = of pixels near markings whose coverage "
          f"stayed on one side of 1/2; 'wrong vs cov' = of pixels near markings, all frames")
    box = _crop_box(np.sum(flip_maps[1], axis=0))
    _strip(Path(a.png), labels, flip_maps, cov, box, min(a.frames, 6))
    print(f"strip: rows {box[0].start}-{box[0].stop}, columns {box[1].start}-{box[1].stop}")
    print(f"wrote {a.png}")


if __name__ == "__main__":
    main()
