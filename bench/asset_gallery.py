"""Render one of each procedural asset to a PNG contact sheet (Pillow only, no Blender).

Each tile shows an asset in four orthographic views, faces z-buffered (a per-pixel depth
test rather than painter's sorting, so 1.5 cm proud glass is not hidden behind its own
body panel) and shaded by their normal:

    3/4 view (material colours) | side view from -y (material colours)
    front view from +x (material colours) | top view (class colours)

Usage::

    python bench/asset_gallery.py out/gallery.png [--seed 3] [--only car truck]

Prints the triangle count and size of every asset it draws.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from assets_procedural import catalog
from generator.geometry import face_normals
from generator.labels import class_table
from generator.materials import material_table

TILE = 300          # pixels per view
LIGHT = np.array([-0.4, -0.6, 0.7]) / np.linalg.norm([-0.4, -0.6, 0.7])

L_SHAPE = np.array([[-10, -8], [10, -8], [10, 0], [0, 0], [0, 8], [-10, 8]], float)
RECT = np.array([[-7, -5], [7, -5], [7, 5], [-7, 5]], float)
SMALL = np.array([[-5, -4], [5, -4], [5, 4], [-5, 4]], float)

#: (label, kind, params) of the assets drawn
EXAMPLES = [
    ("building flat brick", "building", dict(footprint=RECT, height=16.0, facade="brick")),
    ("building glass", "building", dict(footprint=RECT, height=22.0, facade="glass")),
    ("building plaster shops", "building", dict(footprint=RECT, height=13.0, facade="plaster")),
    ("building L concrete", "building", dict(footprint=L_SHAPE, height=22.0, facade="concrete")),
    ("building gable plaster", "building", dict(footprint=SMALL, height=6.5, roof="gable")),
    ("building hip plaster", "building", dict(footprint=SMALL, height=6.5, roof="hip", floor_height=3.0)),
    ("tree plane 11 m", "tree", dict(height=11.0, species="plane")),
    ("tree linden 9 m", "tree", dict(height=9.0, species="linden")),
    ("tree birch 10 m", "tree", dict(height=10.0, species="birch")),
    ("tree young 5 m", "tree", dict(height=5.0, species="young")),
    ("tree conifer 12 m", "tree", dict(height=12.0, species="conifer")),
    ("bush 1.2 m", "bush", dict(size=1.2)),
    ("hedge 6 m", "hedge", dict(length=6.0)),
    ("lamp_post", "lamp_post", dict()),
    ("traffic_light post", "traffic_light", dict()),
    ("traffic_light arm 5 m", "traffic_light", dict(arm=5.0)),
    ("sign circle", "traffic_sign", dict(shape="circle")),
    ("sign triangle", "traffic_sign", dict(shape="triangle")),
    ("sign octagon", "traffic_sign", dict(shape="octagon")),
    ("sign diamond", "traffic_sign", dict(shape="diamond")),
    ("fence bars 5 m", "fence", dict(length=5.0, style="bars")),
    ("fence pickets 5 m", "fence", dict(length=5.0, height=1.1, style="pickets")),
    ("fence panels 5 m", "fence", dict(length=5.0, height=1.8, style="panels")),
    ("car sedan", "car", dict(variant="sedan")),
    ("car hatchback", "car", dict(variant="hatchback")),
    ("car estate", "car", dict(variant="estate")),
    ("car suv", "car", dict(variant="suv")),
    ("car van", "car", dict(variant="van")),
    ("car pickup", "car", dict(variant="pickup")),
    ("truck", "truck", dict()),
    ("person standing", "person", dict(height=1.75)),
    ("person walking", "person", dict(height=1.65, pose="walking")),
]


def _view(yaw_deg: float, pitch_deg: float) -> np.ndarray:
    """(3, 3) rows: screen right, screen up, toward the viewer; camera looks from azimuth yaw."""
    yaw, pitch = np.radians(yaw_deg), np.radians(pitch_deg)
    toward = np.array([np.cos(pitch) * np.cos(yaw), np.cos(pitch) * np.sin(yaw), np.sin(pitch)])
    right = np.cross([0, 0, 1.0], toward) if abs(pitch_deg) < 89 else np.array([1.0, 0, 0])
    right /= np.linalg.norm(right)
    return np.stack([right, np.cross(toward, right), toward])


VIEWS = {  # name: (yaw from which we look, pitch)
    "3/4": (-60.0, 25.0),
    "side": (-90.0, 0.0),
    "front": (0.0, 0.0),
    "top": (-90.0, 90.0),
}


def rasterize(tri: np.ndarray, colours: np.ndarray, width: int, height: int) -> np.ndarray:
    """Z-buffered flat-shaded triangles.

    Parameters
    ----------
    tri : (m, 3, 3) float
        Screen x (pixels, right), screen y (pixels, down) and depth (larger = nearer).
    colours : (m, 3) uint8
    width, height : int

    Returns
    -------
    (height, width, 4) uint8 RGBA; alpha 0 where nothing was drawn.
    """
    rgba = np.zeros((height, width, 4), np.uint8)
    zbuf = np.full((height, width), -np.inf)
    for t, c in zip(tri, colours, strict=False):
        x0, y0 = np.floor(t[:, :2].min(0)).astype(int)
        x1, y1 = np.ceil(t[:, :2].max(0)).astype(int)
        x0, y0, x1, y1 = max(x0, 0), max(y0, 0), min(x1, width - 1), min(y1, height - 1)
        if x1 < x0 or y1 < y0:
            continue
        px, py = np.meshgrid(np.arange(x0, x1 + 1) + 0.5, np.arange(y0, y1 + 1) + 0.5)
        (ax, ay, az), (bx, by, bz), (cx, cy, cz) = t
        area = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
        if abs(area) < 1e-9:
            continue
        w0 = ((bx - px) * (cy - py) - (by - py) * (cx - px)) / area
        w1 = ((cx - px) * (ay - py) - (cy - py) * (ax - px)) / area
        w2 = 1.0 - w0 - w1
        inside = (w0 >= -1e-6) & (w1 >= -1e-6) & (w2 >= -1e-6)
        z = w0 * az + w1 * bz + w2 * cz
        sub = zbuf[y0:y1 + 1, x0:x1 + 1]
        win = inside & (z > sub)
        sub[win] = z[win]
        rgba[y0:y1 + 1, x0:x1 + 1][win] = (*c, 255)
    return rgba


def draw_view(img: Image.Image, box: tuple[int, int, int, int], mesh, view: str, palette: np.ndarray,
              colour_index: np.ndarray) -> None:
    """Draw ``mesh`` orthographically into ``box`` (x0, y0, x1, y1) of ``img`` (z-buffered)."""
    rot = _view(*VIEWS[view])
    if view == "top":
        rot = np.eye(3)
    p = mesh.vertices @ rot.T
    lo, hi = p[:, :2].min(0), p[:, :2].max(0)
    x0, y0, x1, y1 = box
    w, h = x1 - x0, y1 - y0
    scale = 0.9 * min(w / max(hi[0] - lo[0], 1e-6), h / max(hi[1] - lo[1], 1e-6))
    centre = (lo + hi) / 2
    scr = np.stack([w / 2 + (p[:, 0] - centre[0]) * scale, h / 2 - (p[:, 1] - centre[1]) * scale, p[:, 2]], 1)
    n = face_normals(mesh)
    facing = n @ rot[2]
    shade = 0.35 + 0.65 * np.clip(np.abs(n @ LIGHT), 0, 1)
    shade = np.where(facing >= 0, shade, shade * 0.5)
    colours = np.clip(palette[colour_index].astype(float) * shade[:, None], 0, 255).astype(np.uint8)
    tile = Image.fromarray(rasterize(scr[mesh.faces], colours, w, h), "RGBA")
    img.paste(tile, (x0, y0), tile)
    ImageDraw.Draw(img).text((x0 + 4, y1 - 14), view, fill=(90, 90, 90))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", type=Path, help="PNG path to write")
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("--only", nargs="*", default=None, help="labels or kinds to draw (default: all)")
    ap.add_argument("--cols", type=int, default=5)
    args = ap.parse_args(argv)
    examples = [e for e in EXAMPLES if not args.only or e[1] in args.only or e[0] in args.only]
    mat_pal = material_table().colors
    cls_pal = class_table().colors
    cols = min(args.cols, len(examples))
    rows = (len(examples) + cols - 1) // cols
    tile_w, tile_h = 2 * TILE, 2 * TILE + 20
    img = Image.new("RGB", (cols * tile_w, rows * tile_h), (235, 238, 242))
    draw = ImageDraw.Draw(img)
    t0 = time.perf_counter()
    total = 0
    for k, (label, kind, params) in enumerate(examples):
        rng = np.random.default_rng(args.seed + k)
        mesh = catalog.build(kind, rng, **params)
        size = mesh.bounds()[1] - mesh.bounds()[0]
        total += mesh.n_faces
        print(f"{label:26s} {mesh.n_faces:6d} tris  size {size[0]:.2f} x {size[1]:.2f} x {size[2]:.2f} m")
        ox, oy = (k % cols) * tile_w, (k // cols) * tile_h
        draw.rectangle([ox, oy, ox + tile_w - 1, oy + tile_h - 1], outline=(180, 180, 180))
        draw.text((ox + 6, oy + 4), f"{label}  {mesh.n_faces} tris  {size[0]:.1f}x{size[1]:.1f}x{size[2]:.1f} m",
                  fill=(0, 0, 0))
        for j, view in enumerate(("3/4", "side", "front", "top")):
            vx, vy = ox + (j % 2) * TILE, oy + 20 + (j // 2) * TILE
            pal, idx = (cls_pal, mesh.face_class) if view == "top" else (mat_pal, mesh.face_material)
            draw_view(img, (vx, vy, vx + TILE, vy + TILE), mesh, view, pal, idx)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    img.save(args.out)
    print(
        f"{len(examples)} assets, {total} triangles, built and drawn in {time.perf_counter() - t0:.1f} s -> {args.out}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
