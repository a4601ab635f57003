"""Render the cars and people of issue 14 with Cycles: RGB beside the class and instance labels.

Shots of a small hand-made scene on an asphalt square:

* cars: one of each body type, each with a paint drawn from the fleet distribution, seen
  3/4 from the front (even) or the rear (odd);
* people: a row of pedestrians (both poses, every arm action and garment that the seeds give),
  each with an outfit drawn from the clothing palettes.

Each shot is one row of the PNG: RGB (as the camera shows it) | class colours | instance ids.
The paint / outfit names and triangle counts are printed, with the render time per shot.

Usage::

    python bench/gallery_looks.py OUT.png [--seed 3] [--size 480x270] [--samples 16]
"""

from __future__ import annotations

import argparse
import dataclasses
import tempfile
import time
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from assets_procedural import catalog
from assets_procedural.vehicle import CAR_VARIANTS
from generator import geometry as M
from generator.labels import class_table
from generator.layout.placement.appearance import fleet_paint, outfit
from generator.rng import stream
from generator.world import rig
from generator.world.scene import OrientedBox, SceneModel, SceneObject
from generator.world.scene import Path as RoutePath

CAR_GAP_M = 14.0


def _shots() -> dict:
    """name -> (camera position, yaw deg, pitch-down deg): a 3/4 view of each car (front for even,
    rear for odd ones), then the people in two halves."""
    out = {}
    for i, body in enumerate(CAR_VARIANTS):
        dx = 4.4 if i % 2 == 0 else -4.4
        out[f"{body} {'front' if dx > 0 else 'rear'} 3/4"] = (
            (dx, CAR_GAP_M * i - 3.6, 1.6), float(np.degrees(np.arctan2(3.6, -dx))), 8.0)
    out["people 0-4"] = ((-10.0, 3.0, 1.2), 180.0, 3.0)
    out["people 5-9"] = ((-10.0, -3.0, 1.2), 180.0, 3.0)
    return out


def _scene(seed: int) -> tuple[SceneModel, list[str]]:
    """Cars 12 m apart along y at x = 0 (facing +x), people in a row along y at x = -14."""
    protos, objs, notes = {}, [], []

    def add(name, kind, mesh, T, inst, attrs):
        protos[name] = mesh
        v = M.apply(T, mesh.vertices)
        lo, hi = v.min(0), v.max(0)
        cls = catalog.MAIN_CLASS.get(kind, "road")
        objs.append(SceneObject(len(objs), name, kind, cls, inst, name, T,
                                OrientedBox(tuple((lo + hi) / 2), tuple(hi - lo), 0.0), None, attrs))

    add("ground", "road_surface", M.rect(-200, -200, 200, 200, 0.0, "road", "asphalt"), np.eye(4), 0, {})
    for i, body in enumerate(CAR_VARIANTS):
        mesh = catalog.build("car", stream(seed, "gallery", "car", i), variant=body)
        attrs = fleet_paint(stream(seed, "gallery", "paint", i))
        add(f"car_{body}", "car", mesh, M.pose(0.0, CAR_GAP_M * i, 0.0), 1 + i, attrs)
        notes.append(f"{body:<10} {attrs['paint']:<7} {mesh.n_faces:5d} tris  "
                     f"{'x'.join(f'{s:.2f}' for s in mesh.bounds()[1] - mesh.bounds()[0])} m")
    for j in range(10):
        g = stream(seed, "gallery", "person", j)
        h = float(g.uniform(1.55, 1.95))
        pose = "walking" if j % 2 else "standing"
        mesh = catalog.build("person", g, height=h, pose=pose)
        attrs = outfit(stream(seed, "gallery", "outfit", j))
        add(f"person_{j}", "person", mesh, M.pose(-14.0, 5.4 - 1.2 * j, 0.0, np.radians(-30 + 20 * (j % 3))), 20 + j,
            attrs)
        notes.append(f"person {j} {pose:<8} {h:.2f} m {mesh.n_faces:4d} tris  {attrs['outfit']}")
    xs = np.arange(0.0, 10.0, 1.0)
    paths = [RoutePath("gallery", np.c_[xs, np.zeros_like(xs), np.zeros_like(xs)], np.zeros_like(xs), xs.copy(), False)]
    return SceneModel(seed, "gallery", np.array([[-200.0, -200.0], [200.0, 200.0]]), protos, {}, objs, paths), notes


def _instances(inst: np.ndarray) -> np.ndarray:
    """(H, W) instance ids -> (H, W, 3) uint8, a fixed random colour per id (0 dark)."""
    pal = np.random.default_rng(1).integers(60, 255, (65536, 3)).astype(np.uint8)
    pal[0] = 25
    return pal[inst]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out", help="the gallery PNG to write")
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("--size", default="480x270")
    ap.add_argument("--samples", type=int, default=16)
    a = ap.parse_args()

    from generator.blender.renderer import Renderer
    from generator.previews.preview import colorize, display_rgb
    from generator.spec import load_spec
    from generator.spec.render import load_render_config
    from generator.weather import Lighting

    w, h = (int(v) for v in a.size.split("x"))
    spec = load_spec(Path(__file__).resolve().parents[1] / "scenes" / "test_town.json")
    cfg = dataclasses.replace(load_render_config("test"), resolution=(w, h), samples=a.samples, max_bounces=4)
    scene, notes = _scene(a.seed)
    print("\n".join(notes))
    r = Renderer(scene, spec, cfg, Path(tempfile.mkdtemp(prefix="ug_gallery_")))
    r.set_conditions(Lighting("day", sun_elevation_deg=40.0, sun_azimuth_deg=215.0))
    rows = []
    for name, (xyz, yaw, pitch) in _shots().items():
        T = rig.camera_extrinsics(xyz, (0.0, 0.0, yaw), (0.0, np.radians(pitch), 0.0))
        t = time.perf_counter()
        out = r.render(T, seed=0, light_info={})
        print(f"shot {name}: rendered in {time.perf_counter() - t:.1f} s ({w}x{h}, {a.samples} spp)")
        panels = [display_rgb(out.rgb), colorize(out.labels.class_id), _instances(out.labels.instance)]
        row = np.concatenate([np.pad(p, ((0, 0), (0, 4), (0, 0)), constant_values=255) for p in panels], 1)
        img = Image.fromarray(row)
        ImageDraw.Draw(img).text((6, 4), f"{name}: RGB | class | instance", fill=(255, 255, 0))
        rows.append(np.asarray(img))
    sheet = np.concatenate(rows, 0)
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(sheet).save(a.out)
    classes = sorted({class_table()[int(c)].name for c in np.unique(out.labels.class_id)})
    print(f"-> {a.out}; classes in the last shot: {', '.join(classes)}")


if __name__ == "__main__":
    main()
