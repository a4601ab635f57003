"""Top-down map of a SceneModel: every upward-facing triangle rasterised with a z-buffer,
coloured by class (``class_table().colors``) and lightly shaded by its slope, with route 0,
frame markers, a legend and a scale bar.

Pure numpy rasteriser (point sampling at pixel centres) plus Pillow for the overlays.
"""

from __future__ import annotations

import logging

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from generator.labels import class_table
from generator.world.scene import SceneModel

log = logging.getLogger(__name__)

LIGHT = np.array([-1.0, 1.0, 2.0]) / np.sqrt(6.0)   #: sun from the north-west, for slope shading
ROUTE_RGB = (0, 230, 255)
MARKER_RGB = (255, 255, 0)
PANEL_W = 230
CHUNK = 3_000_000   #: candidate pixels per rasterisation batch


def choose_scale(bounds: np.ndarray, max_px: int = 4000) -> float:
    """Pixels per metre: 8 for small towns, less for big ones so the map stays under ``max_px``
    (4 px/m down to 1000 m across)."""
    extent = float(np.max(bounds[1] - bounds[0]))
    return float(min(8.0, max_px / extent))


def rasterize(vertices: np.ndarray, faces: np.ndarray, values: np.ndarray, bounds: np.ndarray,
              ppm: float) -> tuple[np.ndarray, np.ndarray]:
    """Top-down z-buffer of the upward-facing triangles.

    Parameters
    ----------
    vertices : (V, 3) float32
        World frame, metres.
    faces : (F, 3) uint32
    values : (F,) int64
        A value per triangle (e.g. an index into a colour table).
    bounds : (2, 2) float64
        [[xmin, ymin], [xmax, ymax]] world metres of the image.
    ppm : float
        Pixels per metre.

    Returns
    -------
    top : (H, W) int64
        Value of the highest triangle covering each pixel centre, -1 where none.
    zbuf : (H, W) float32
        Its height, metres (-inf where none). Row 0 is the north edge.
    """
    (x0, y0), (x1, y1) = bounds
    W, H = int(np.ceil((x1 - x0) * ppm)), int(np.ceil((y1 - y0) * ppm))
    tri = vertices[faces].astype(np.float64)
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    up = n[:, 2] > 1e-9
    tri, values = tri[up], values[up]
    px = np.stack([(tri[..., 0] - x0) * ppm, (y1 - tri[..., 1]) * ppm], -1)   # (f, 3, 2)
    lo = np.clip(np.floor(px.min(1) - 0.5).astype(np.int64) + 1, 0, [W - 1, H - 1])
    hi = np.clip(np.floor(px.max(1) - 0.5).astype(np.int64), -1, [W - 1, H - 1])
    wh = np.maximum(hi - lo + 1, 0)
    count = wh[:, 0] * wh[:, 1]
    top = np.full(H * W, -1, np.int64)
    zbuf = np.full(H * W, -np.inf, np.float32)
    ends = np.cumsum(count)
    start = 0
    while start < len(count):
        base = ends[start - 1] if start else 0
        stop = int(np.searchsorted(ends, base + CHUNK, side="right"))
        stop = max(stop, start + 1)
        _raster_batch(px[start:stop], tri[start:stop, :, 2], values[start:stop], lo[start:stop],
                      wh[start:stop], count[start:stop], W, top, zbuf)
        start = stop
    return top.reshape(H, W), zbuf.reshape(H, W)


def _raster_batch(px, z, values, lo, wh, count, W, top, zbuf) -> None:
    total = int(count.sum())
    if total == 0:
        return
    t = np.repeat(np.arange(len(count)), count)
    off = np.arange(total) - np.repeat(np.cumsum(count) - count, count)
    cx = lo[t, 0] + off % wh[t, 0]
    cy = lo[t, 1] + off // wh[t, 0]
    p = np.stack([cx + 0.5, cy + 0.5], -1)
    a, b, c = px[t, 0], px[t, 1], px[t, 2]
    v0, v1, v2 = b - a, c - a, p - a
    den = v0[:, 0] * v1[:, 1] - v1[:, 0] * v0[:, 1]
    den = np.where(np.abs(den) < 1e-12, 1e-12, den)
    l1 = (v2[:, 0] * v1[:, 1] - v1[:, 0] * v2[:, 1]) / den
    l2 = (v0[:, 0] * v2[:, 1] - v2[:, 0] * v0[:, 1]) / den
    inside = (l1 >= -1e-9) & (l2 >= -1e-9) & (l1 + l2 <= 1 + 1e-9)
    t, l1, l2 = t[inside], l1[inside], l2[inside]
    zz = z[t, 0] * (1 - l1 - l2) + z[t, 1] * l1 + z[t, 2] * l2
    pix = (cy[inside] * W + cx[inside])
    order = np.lexsort((zz, pix))
    pix, zz, t = pix[order], zz[order], t[order]
    last = np.r_[pix[1:] != pix[:-1], True]
    pix, zz, t = pix[last], zz[last], t[last]
    better = zz > zbuf[pix]
    zbuf[pix[better]] = zz[better]
    top[pix[better]] = values[t[better]]


def _font(size: int):
    try:
        return ImageFont.load_default(size=size)
    except TypeError:  # Pillow < 10.1
        return ImageFont.load_default()


def render_map(scene: SceneModel, ppm: float | None = None, marker_spacing_m: float = 12.0,
               title: str = "") -> Image.Image:
    """The top-down class map of ``scene`` as an RGB image (legend panel on the right).

    The map covers ``scene.bounds``: the built town (streets and the lots round the outer
    ring road) and its terrain margin. The ground that runs on for kilometres beyond it (to
    the horizon) is cropped; its triangles cost the rasteriser only their clipped bounding boxes.

    Parameters
    ----------
    ppm : float, optional
        Pixels per metre (default :func:`choose_scale`).
    marker_spacing_m : float
        Distance between the frame markers drawn on route 0 (the spec's ``paths.spacing_m``).
    """
    table = class_table()
    bounds = np.asarray(scene.bounds, np.float64)
    ppm = choose_scale(bounds) if ppm is None else float(ppm)
    V, F, cls = scene.vertices, scene.faces, scene.face_class.astype(np.int64)
    tri = V[F].astype(np.float64)
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)
    shade = 0.55 + 0.45 * np.clip(n @ LIGHT, 0, 1) / float(LIGHT[2])
    shade_q = np.clip(np.round(shade * 31), 0, 31).astype(np.int64)
    palette = (table.colors[None, :, :].astype(np.float64) * (np.arange(32) / 31)[:, None, None])
    palette = np.clip(palette, 0, 255).astype(np.uint8).reshape(-1, 3)          # (32 * n_classes, 3)
    top, _ = rasterize(V, F, shade_q * len(table) + cls, bounds, ppm)
    rgb = np.where(top[..., None] >= 0, palette[np.maximum(top, 0)], np.uint8(30)).astype(np.uint8)
    H, W = top.shape
    k = max(1.0, H / 1100)            # legend scale: readable next to big maps
    img = Image.new("RGB", (W + int(PANEL_W * k), max(H, int(560 * k))), (245, 245, 245))
    img.paste(Image.fromarray(rgb), (0, 0))
    draw = ImageDraw.Draw(img)

    def to_px(xy: np.ndarray) -> list[tuple[float, float]]:
        return [((x - bounds[0, 0]) * ppm, (bounds[1, 1] - y) * ppm) for x, y in xy]

    if scene.paths:
        path = scene.paths[0]
        pts = to_px(np.vstack([path.points[:, :2], path.points[:1, :2]]))
        draw.line(pts, fill=ROUTE_RGB, width=max(2, int(ppm / 3)))
        s = np.arange(0.0, path.length(), marker_spacing_m)
        pos, hd = path.at(s)
        r = max(3.0, ppm * 0.9)
        for (x, y), h in zip(to_px(pos[:, :2]), hd, strict=False):
            tip = (x + r * 1.6 * np.cos(h), y - r * 1.6 * np.sin(h))
            left = (x + r * np.cos(h + 2.4), y - r * np.sin(h + 2.4))
            rr = (x + r * np.cos(h - 2.4), y - r * np.sin(h - 2.4))
            draw.polygon([tip, left, rr], fill=MARKER_RGB, outline=(0, 0, 0))
        x, y = to_px(pos[:1, :2])[0]
        draw.ellipse([x - r * 1.5, y - r * 1.5, x + r * 1.5, y + r * 1.5], outline=(255, 0, 0), width=3)
    _legend(draw, W, table, scene, ppm, title, k)
    return img


def _legend(draw: ImageDraw.ImageDraw, x0: int, table, scene: SceneModel, ppm: float, title: str,
            k: float = 1.0) -> None:
    """Class swatches (classes with geometry), route and frame symbols, scale bar; ``k`` scales it all."""
    f, fs = _font(int(15 * k)), _font(int(12 * k))
    u = lambda v: int(round(v * k))   # noqa: E731 - legend units
    y = u(10)
    if title:
        draw.text((x0 + u(12), y), title, fill=(0, 0, 0), font=f)
        y += u(24)
    present = set(np.unique(scene.face_class).tolist())
    for cid, name in enumerate(table.names):
        if cid not in present:
            continue
        draw.rectangle([x0 + u(12), y, x0 + u(34), y + u(14)], fill=tuple(int(c) for c in table.colors[cid]),
                       outline=(0, 0, 0))
        draw.text((x0 + u(42), y), name, fill=(0, 0, 0), font=fs)
        y += u(20)
    y += u(6)
    draw.line([(x0 + u(12), y + u(7)), (x0 + u(34), y + u(7))], fill=ROUTE_RGB, width=u(4))
    draw.text((x0 + u(42), y), "route 0", fill=(0, 0, 0), font=fs)
    y += u(20)
    draw.polygon([(x0 + u(30), y + u(7)), (x0 + u(16), y), (x0 + u(16), y + u(14))], fill=MARKER_RGB, outline=(0, 0, 0))
    draw.text((x0 + u(42), y), "frame (driving dir.)", fill=(0, 0, 0), font=fs)
    y += u(20)
    draw.ellipse([x0 + u(16), y, x0 + u(30), y + u(14)], outline=(255, 0, 0), width=u(2))
    draw.text((x0 + u(42), y), "frame 0", fill=(0, 0, 0), font=fs)
    y += u(34)
    metres = next((m for m in (200, 100, 50, 20, 10, 5, 2, 1) if m * ppm <= u(PANEL_W - 40)), 1)
    bar = metres * ppm
    draw.rectangle([x0 + u(12), y, x0 + u(12) + bar, y + u(8)], fill=(0, 0, 0))
    draw.rectangle([x0 + u(12) + bar / 2, y + 1, x0 + u(12) + bar - 1, y + u(8) - 1], fill=(255, 255, 255))
    draw.text((x0 + u(12), y + u(12)), f"{metres} m  ({ppm:.1f} px/m)", fill=(0, 0, 0), font=fs)
    y += u(34)
    draw.text((x0 + u(12), y), "north up", fill=(0, 0, 0), font=fs)
