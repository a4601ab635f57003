"""Cost of wet renders before and after issue 14 (item 5), side by side. (The label passes' cost is measured in the
worker's order, batched, by ``bench/label_cost.py``.)

One process, one town, the same camera poses, two Blender scenes built one after the other:

* before: the wet shader as it was (4D puddle noise, two 4D Voronoi ripple fields, the puddle
  mask inside the bump height -- :func:`legacy_wet_surface` below is a verbatim copy);
* after: the shipped wet shader (:mod:`generator.blender.wet`).

Per pose the RGB pass is rendered dry, wet, dry, wet (the production order switches shaders
between them, so each render pays its shader recompile) and the medians are printed, with
wet / dry. ``--diagnose`` adds both scenes at 0 bounces:
if the wet/dry ratio stays there, the cost is shading, not light paths.

    python bench/render_cost.py [--config preview] [--poses 2] [--diagnose] [--time-of-day night]
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics
import tempfile
from pathlib import Path

import numpy as np


def legacy_wet_surface(g, color, roughness, normal=None, puddles: bool = True):
    """The wet modifier before issue 14 item 5 (verbatim), for the "before" column."""
    from generator.blender.controls import CONTROL

    wet = g.attr(CONTROL["wetness"], "VIEW_LAYER")
    seed = g.attr(CONTROL["puddle_seed"], "VIEW_LAYER")
    mask = wet
    if puddles:
        pud = g.noise(g.coords("Object"), scale=0.08, detail=3, roughness=0.6, w=seed)
        pud = g.math("MULTIPLY", g.smooth(pud, 0.56, 0.6), wet)
        ripple = g.math("SUBTRACT", g.voronoi(scale=6.0, w=g.mul(seed, 7.0)), g.voronoi(scale=6.5, w=g.mul(seed, 7.0)))
        normal = g.bump(g.mul(ripple, pud), strength=0.15, distance=0.01, normal=normal)
        mask = g.math("MAXIMUM", wet, pud)
        roughness = g.lerp(pud, roughness, 0.02)
    color = g.mix(g.mul(mask, 0.55), color, g.mix(0.5, color, (0, 0, 0), "MULTIPLY"))
    roughness = g.lerp(g.mul(wet, 0.8), roughness, 0.08)
    return color, roughness, normal


def _phase(name, wet_fn, scene, spec, cfg, poses, keep: dict | None, diagnose: bool, tod: str) -> dict:
    from generator.blender import passes, recipes, session
    from generator.blender.renderer import Renderer
    from generator.weather import draw_lighting, frame_wetness

    shipped = recipes.wet_surface
    recipes.wet_surface = wet_fn
    try:
        r = Renderer(scene, spec, cfg, Path(tempfile.mkdtemp(prefix="ug_cost_")))
    finally:
        recipes.wet_surface = shipped
    out = {"dry": [], "wet": []}
    for f in poses:
        light = draw_lighting(spec, f.index, tod)
        wetness, puddles = frame_wetness(spec, f.index)
        r.place_camera(f.T_world_camera)
        r.set_conditions(light)
        r.render_rgb(seed=f.index)  # warm-up: BVH and first shader compile, paid once per process
        for _ in range(2):
            for kind, w in (("dry", 0.0), ("wet", wetness)):
                r.set_conditions(light, w, puddles)
                rgb, s = r.render_rgb(seed=f.index)
                out[kind].append(s)
                if keep is not None and f is poses[0]:
                    keep[f"{name}_{kind}"] = rgb
        if diagnose:
            flat = dataclasses.replace(cfg, max_bounces=0)
            for kind, w in (("dry", 0.0), ("wet", wetness)):
                r.set_conditions(light, w, puddles)
                out.setdefault(f"{kind}_0_bounces", []).append(
                    passes.render_rgb(r.bscene, r.handles, flat, f.index, r.scratch)[1])
    session.reset()
    return {k: statistics.median(v) for k, v in out.items()}


def _look(path: Path, images: dict) -> None:
    from PIL import Image, ImageDraw

    from generator.previews.preview import tonemap

    names = ["before_dry", "before_wet", "after_wet"]
    tiles = [tonemap(images[n]) for n in names]
    tiles = [t if t.dtype == np.uint8 else (np.clip(t, 0, 1) * 255).astype(np.uint8) for t in tiles]
    h, w = tiles[0].shape[:2]
    crops = [np.kron(t[h // 2:, w // 4: 3 * w // 4], np.ones((2, 2, 1), np.uint8)) for t in tiles]
    canvas = Image.fromarray(np.concatenate([np.concatenate(tiles, 1), np.concatenate(crops, 1)], 0))
    d = ImageDraw.Draw(canvas)
    for i, n in enumerate(["dry", "wet before", "wet after"]):
        d.text((i * w + 6, 6), n, fill=(255, 40, 40))
    path.parent.mkdir(parents=True, exist_ok=True)
    canvas.save(path)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--spec", default="scenes/default_town.json")
    ap.add_argument("--config", default="preview")
    ap.add_argument("--poses", type=int, default=2)
    ap.add_argument("--first", type=int, default=5)
    ap.add_argument("--diagnose", action="store_true")
    ap.add_argument("--time-of-day", default="day", choices=["day", "night"])
    ap.add_argument("--png", default=None, help="also write the dry/wet crops side by side to this PNG")
    a = ap.parse_args()

    from generator.blender.wet import wet_surface
    from generator.layout.assemble import build_scene
    from generator.spec import load_spec
    from generator.spec.render import load_render_config
    from generator.world.rig import Rig

    spec, cfg = load_spec(a.spec), load_render_config(a.config)
    scene = build_scene(spec)
    rig = Rig.from_spec(spec, scene)
    poses = [rig.frame(a.first + 7 * i) for i in range(a.poses)]
    images: dict = {}
    res = {"before": _phase("before", legacy_wet_surface, scene, spec, cfg, poses, images, a.diagnose, a.time_of_day),
           "after": _phase("after", wet_surface, scene, spec, cfg, poses, images, a.diagnose, a.time_of_day)}
    print(f"{cfg.name} {cfg.width}x{cfg.height}, {cfg.samples} spp, {a.time_of_day}, "
          f"{a.poses} poses x 2 renders each, medians (s)")
    print(f"{'':<8}{'dry RGB':>9}{'wet RGB':>9}{'wet/dry':>9}"
          + (f"{'dry 0b':>9}{'wet 0b':>9}{'ratio':>7}" if a.diagnose else ""))
    for name, m in res.items():
        line = f"{name:<8}{m['dry']:>9.2f}{m['wet']:>9.2f}{m['wet'] / m['dry']:>9.2f}"
        if a.diagnose:
            line += (
                f"{m['dry_0_bounces']:>9.2f}{m['wet_0_bounces']:>9.2f}{m['wet_0_bounces'] / m['dry_0_bounces']:>7.2f}"
            )
        print(line)
    print("the machine's load is shared: compare within a run.")
    if a.png:
        _look(Path(a.png), images)
        print(f"wrote {a.png}")


if __name__ == "__main__":
    main()
