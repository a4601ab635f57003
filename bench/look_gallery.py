"""Render the looks of issue 14 item 4 in Blender: RGB beside the label view, one row per shot.

    python bench/look_gallery.py OUT.png [--spec scenes/default_town.json]
                                 [--width 480] [--samples 16] [--only trees facades road]

Shots, all in the town the spec builds (day, clear, the spec's seed):

* ``trees``   -- a tree of each species in the town, the camera 1.6 m up, 1.6 crown heights away;
* ``facades`` -- the buildings with shop fronts and balconies, seen from the sidewalk across the street;
* ``road``    -- stretches of road seen from 2.2 m up, looking down the lane, and one from 14 m above
  (patches, sealed seams, cracks, manholes, stains);

Each row: the RGB render (``preview``-like Cycles settings) and the label pass coloured with the
class palette (what the masks hold: crowns and hedges as their hull proxies). Prints per shot what
it shows and the render seconds beside the Blender scene build time measured in the same run.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from generator.labels import class_table  # noqa: E402
from generator.materials import material_table  # noqa: E402
from generator.spec import load_spec  # noqa: E402
from generator.spec.render import load_render_config  # noqa: E402
from generator.weather import Lighting  # noqa: E402


def look_at(eye, target) -> np.ndarray:
    """(4, 4) optical-frame pose (x right, y down, z forward) at ``eye`` looking at ``target``."""
    eye, target = np.asarray(eye, float), np.asarray(target, float)
    z = target - eye
    z /= np.linalg.norm(z)
    x = np.cross(z, [0.0, 0.0, 1.0])
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, y, z, eye
    return T


GROUND_KINDS = ("street", "intersection", "sidewalk", "corner", "lot_ground", "terrain", "horizon")


def _materials_of(scene, obj) -> set[str]:
    names = [r.name for r in material_table().rows]
    return {names[i] for i in np.unique(scene.prototypes[obj.prototype].face_material)}


def _clear_eye(scene, eye, target) -> bool:
    """True when nothing of the town stands within 0.6 m of the camera or 3 m along the first
    stretch of its sight line (object boxes, 2D)."""
    for o in scene.objects:
        if o.kind in GROUND_KINDS or o.box is None:
            continue
        c, size = np.asarray(o.box.center[:2]), np.asarray(o.box.size[:2])
        for t in np.linspace(0.0, 3.0, 7):
            p = eye[:2] + (target[:2] - eye[:2]) / np.linalg.norm(target[:2] - eye[:2]) * t
            d = p - c
            cs, sn = np.cos(o.box.yaw), np.sin(o.box.yaw)
            lx, ly = abs(d[0] * cs + d[1] * sn), abs(-d[0] * sn + d[1] * cs)
            if lx < size[0] / 2 + 0.6 and ly < size[1] / 2 + 0.6 and o.box.center[2] - o.box.size[2] / 2 < 2.0:
                return False
    return True


def tree_shots(scene) -> list[tuple[str, np.ndarray]]:
    """One shot per species found in the town (species told apart by their materials and shape)."""
    shots, seen = [], set()
    for o in scene.objects:
        if o.kind != "tree":
            continue
        mats = _materials_of(scene, o)
        m = scene.prototypes[o.prototype]
        ext = m.bounds()[1] - m.bounds()[0]
        species = ("conifer" if "needles" in mats else "birch" if "bark_birch" in mats
                   else "broad crown" if ext[0] > 0.75 * ext[2] else "upright / young")
        if species in seen:
            continue
        base = o.transform[:3, 3]
        h = float(ext[2])
        for ang in np.linspace(0, 2 * np.pi, 12, endpoint=False):
            eye = base + [np.cos(ang) * 1.5 * h, np.sin(ang) * 1.5 * h, 1.6]
            target = base + [0.0, 0.0, 0.5 * h]
            if _clear_eye(scene, eye, target):
                shots.append((f"tree: {species}, {h:.1f} m", look_at(eye, target)))
                seen.add(species)
                break
    return shots


def facade_shots(scene, n: int = 2) -> list[tuple[str, np.ndarray]]:
    """Buildings with shop fronts (awnings) and with balconies, from across the street."""
    shots = []
    for want in ("awning", "balcony_metal", "facade_glass"):
        for o in scene.objects:
            if o.kind != "building" or want not in _materials_of(scene, o):
                continue
            T = o.transform
            m = scene.prototypes[o.prototype]
            lo, hi = m.bounds()
            front = T[:3, :3] @ np.array([0.0, -1.0, 0.0])
            centre = T[:3, :3] @ np.array([(lo[0] + hi[0]) / 2, lo[1], 0.0]) + T[:3, 3]
            eye = centre + front * 22.0 + T[:3, :3] @ np.array([6.0, 0.0, 0.0])
            eye[2] = T[2, 3] + 1.7
            target = centre + [0.0, 0.0, min(hi[2] * 0.35, 8.0)]
            if _clear_eye(scene, eye, target):
                shots.append((f"facade: {o.attrs.get('facade')} with {want.replace('_', ' ')}", look_at(eye, target)))
                break
    return shots[:n + 1]


def road_shots(scene) -> list[tuple[str, np.ndarray]]:
    path = max(scene.paths, key=lambda p: p.length())
    out = []
    for s, ahead in ((0.18, 14.0), (0.55, 14.0), (0.33, 6.0), (0.8, 6.0)):
        (p,), (hd,) = path.at(s * path.length())
        d = np.array([np.cos(hd), np.sin(hd), 0.0])
        eye = p + [0.0, 0.0, 2.2]
        out.append((f"road: {path.name} at {s * path.length():.0f} m", look_at(eye, p + d * ahead)))
    (p,), (hd,) = path.at(0.4 * path.length())
    d = np.array([np.cos(hd), np.sin(hd), 0.0])
    out.append(("road from 14 m above (manholes, patches, cracks)",
                look_at(p + [0.0, 0.0, 14.0] - 0.5 * d, p + d * 1.0)))
    return out


def label_rgb(class_id: np.ndarray) -> np.ndarray:
    return class_table().colors[class_id].astype(np.uint8)


def to_srgb(rgb: np.ndarray) -> np.ndarray:
    x = np.clip(rgb, 0, None)
    x = x / (1 + x)                                          # gentle tone map, the renders are scene-linear
    x = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
    return (np.clip(x * 1.6, 0, 1) * 255).astype(np.uint8)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", type=Path, help="the gallery PNG to write")
    ap.add_argument("--spec", type=Path, default=ROOT / "scenes" / "default_town.json")
    ap.add_argument("--width", type=int, default=480)
    ap.add_argument("--samples", type=int, default=16)
    ap.add_argument("--only", nargs="*", default=["trees", "facades", "road"])
    args = ap.parse_args(argv)

    from generator.blender.renderer import Renderer
    from generator.layout import build_scene

    spec = load_spec(args.spec)
    t0 = time.perf_counter()
    scene = build_scene(spec)
    t_layout = time.perf_counter() - t0
    cfg = dataclasses.replace(load_render_config("preview"), resolution=(args.width, args.width * 2 // 3),
                              samples=args.samples, motion_blur=dataclasses.replace(
                                  load_render_config("preview").motion_blur, enabled=False), camera_model=False)
    shots = []
    if "trees" in args.only:
        shots += tree_shots(scene)
    if "facades" in args.only:
        shots += facade_shots(scene)
    if "road" in args.only:
        shots += road_shots(scene)
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        r = Renderer(scene, spec, cfg, Path(tmp))
        t_build = time.perf_counter() - t0
        r.set_conditions(Lighting("day", 38.0, 135.0))
        rows = []
        for title, T in shots:
            t0 = time.perf_counter()
            frame = r.render(T, spec.seed, {})
            secs = time.perf_counter() - t0
            present = [class_table().names[c] for c in np.unique(frame.labels.class_id)]
            print(f"{title:48s} {secs:6.1f} s  classes: {', '.join(present)}")
            rows.append((title, to_srgb(frame.rgb), label_rgb(frame.labels.class_id)))
    print(f"layout {t_layout:.1f} s, Blender scene build {t_build:.1f} s (baseline for the render seconds above); "
          f"{len(scene.faces)} triangles")
    w, h = cfg.width, cfg.height
    img = Image.new("RGB", (2 * w + 12, len(rows) * (h + 20) + 4), (240, 240, 240))
    draw = ImageDraw.Draw(img)
    for k, (title, rgb, lab) in enumerate(rows):
        y = k * (h + 20)
        draw.text((4, y + 4), title, fill=(0, 0, 0))
        img.paste(Image.fromarray(rgb), (4, y + 18))
        img.paste(Image.fromarray(lab), (w + 8, y + 18))
    args.out.parent.mkdir(parents=True, exist_ok=True)
    img.save(args.out)
    print(f"{len(rows)} shots -> {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
