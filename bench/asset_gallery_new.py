"""Render every asset of the issue-13 classes to one PNG contact sheet (Pillow only, no Blender).

Each tile shows one asset in four orthographic, z-buffered views, shading beside labels:

    3/4 view (material colours) | 3/4 view (class colours)
    side view from -y (material colours) | top view (class colours)

with the classes the asset carries listed under its title. Reuses the rasteriser of
``bench/asset_gallery.py``.

Usage::

    python bench/asset_gallery_new.py [/tmp/gallery_new_classes.png] [--seed 3] [--only bus tram]

Prints the triangle count and size of every asset it draws.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

sys.path.insert(0, str(Path(__file__).resolve().parent))
from asset_gallery import draw_view  # noqa: E402

from assets_procedural import catalog  # noqa: E402
from generator.labels import class_table  # noqa: E402
from generator.materials import material_table  # noqa: E402

TILE = 260

#: (label, kind, params) of the assets drawn
EXAMPLES = [
    ("bicycle city", "bicycle", dict(style="city")),
    ("bicycle sport", "bicycle", dict(style="sport")),
    ("bicycle mtb, leaning", "bicycle", dict(style="mtb", lean_deg=8.0)),
    ("bicyclist city", "bicyclist", dict(style="city")),
    ("bicyclist sport", "bicyclist", dict(style="sport")),
    ("bicyclist mtb", "bicyclist", dict(style="mtb")),
    ("motorcycle naked", "motorcycle", dict(style="naked")),
    ("motorcycle sport", "motorcycle", dict(style="sport")),
    ("motorcycle scooter", "motorcycle", dict(style="scooter")),
    ("motorcyclist naked", "motorcyclist", dict(style="naked")),
    ("motorcyclist sport", "motorcyclist", dict(style="sport")),
    ("motorcyclist scooter", "motorcyclist", dict(style="scooter")),
    ("bus 12 m, 3 doors", "bus", dict(length=12.0, doors=3)),
    ("bus midi", "bus", dict(length=10.6, doors=2)),
    ("tram 3 sections", "tram", dict(sections=3)),
    ("tram 5 sections, curve", "tram", dict(sections=5, bend_deg=6.0)),
    ("rail track 8 m, concrete", "rail_track", dict(length=8.0, sleeper="concrete")),
    ("tram rails in street 6 m", "tram_rails", dict(length=6.0)),
    ("trailer open", "trailer", dict(style="open")),
    ("trailer box", "trailer", dict(style="box")),
    ("box van (class truck)", "box_van", dict(luton=True)),
    ("excavator raised", "construction_vehicle", dict(boom="raised", slew_deg=0.0)),
    ("excavator lowered, slewed", "construction_vehicle", dict(boom="lowered", slew_deg=25.0)),
    ("wall garden 6 m", "wall", dict(length=6.0, style="garden")),
    ("wall retaining 8 m", "wall", dict(length=8.0, style="retaining", height=2.0)),
    ("wall noise 10 m", "wall", dict(length=10.0, style="noise")),
    ("traffic island teardrop", "traffic_island", dict(shape="teardrop")),
    ("traffic island stadium", "traffic_island", dict(shape="stadium")),
    ("median strip 15 m", "median_strip", dict(length=15.0)),
    ("driveway apron", "driveway_apron", dict()),
    ("gravel patch", "gravel_patch", dict()),
    ("bench", "bench", dict(backrest=True)),
    ("bin on post", "bin", dict(style="post")),
    ("bin wheelie", "bin", dict(style="wheelie")),
    ("bollard metal", "bollard", dict(style="metal")),
    ("bollard concrete", "bollard", dict(style="concrete")),
    ("bike rack hoops", "bike_rack", dict(style="hoops", stands=4)),
    ("bike rack grid", "bike_rack", dict(style="grid", stands=3)),
    ("bus shelter", "bus_shelter", dict()),
    ("hydrant pillar", "hydrant", dict(style="pillar")),
    ("hydrant us", "hydrant", dict(style="us")),
    ("advertising column", "advertising_column", dict()),
]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", type=Path, nargs="?", default=Path("/tmp/gallery_new_classes.png"))
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("--only", nargs="*", default=None, help="labels or kinds to draw (default: all)")
    ap.add_argument("--cols", type=int, default=6)
    ap.add_argument("--tile", type=int, default=TILE, help="pixels per view")
    args = ap.parse_args(argv)
    tile = args.tile
    examples = [e for e in EXAMPLES if not args.only or e[1] in args.only or e[0] in args.only]
    mat_pal = material_table().colors
    table = class_table()
    cls_pal = table.colors
    cols = min(args.cols, len(examples))
    rows = (len(examples) + cols - 1) // cols
    head = 34
    tile_w, tile_h = 2 * tile, 2 * tile + head
    img = Image.new("RGB", (cols * tile_w, rows * tile_h), (235, 238, 242))
    draw = ImageDraw.Draw(img)
    t0 = time.perf_counter()
    total = 0
    for k, (label, kind, params) in enumerate(examples):
        mesh = catalog.build(kind, np.random.default_rng(args.seed + k), **params)
        size = mesh.bounds()[1] - mesh.bounds()[0]
        total += mesh.n_faces
        names = [table.names[c] for c in np.unique(mesh.face_class)]
        print(f"{label:28s} {mesh.n_faces:6d} tris  size {size[0]:5.2f} x {size[1]:5.2f} x {size[2]:5.2f} m  "
              f"{', '.join(names)}")
        ox, oy = (k % cols) * tile_w, (k // cols) * tile_h
        draw.rectangle([ox, oy, ox + tile_w - 1, oy + tile_h - 1], outline=(180, 180, 180))
        draw.text((ox + 6, oy + 3), f"{label}  {mesh.n_faces} tris  {size[0]:.2f}x{size[1]:.2f}x{size[2]:.2f} m",
                  fill=(0, 0, 0))
        x = ox + 6
        for c in np.unique(mesh.face_class):
            draw.rectangle([x, oy + 19, x + 10, oy + 29], fill=tuple(int(v) for v in cls_pal[c]), outline=(0, 0, 0))
            draw.text((x + 14, oy + 18), table.names[c], fill=(40, 40, 40))
            x += 20 + 7 * len(table.names[c])
        for j, (view, labels) in enumerate((("3/4", False), ("3/4", True), ("side", False), ("top", True))):
            vx, vy = ox + (j % 2) * tile, oy + head + (j // 2) * tile
            pal, idx = (cls_pal, mesh.face_class) if labels else (mat_pal, mesh.face_material)
            draw_view(img, (vx, vy, vx + tile, vy + tile), mesh, view, pal, idx)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    img.save(args.out)
    print(
        f"{len(examples)} assets, {total} triangles, built and drawn in {time.perf_counter() - t0:.1f} s -> {args.out}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
