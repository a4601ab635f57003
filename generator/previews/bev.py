"""Bird's-eye view of one LiDAR scan, coloured by class, with a legend.

Sensor frame seen from above: x (forward) points UP in the image, y (left) points LEFT;
the sensor is at the centre, marked with a small white cross. Points are drawn lowest
first, so roofs, car bodies and crowns cover the ground beneath them; cells with no
point stay black (occlusion shadows behind objects show as black wedges). Points on an
actor moving at their firing time (``moving``) are drawn last, as 3x3 dots of :data:`MOVING_RGB`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numba import njit
from PIL import Image, ImageDraw

from generator.atomic import atomic_path
from generator.labels import class_table

#: Colour of moving points: pure green, far from every class colour of the table.
MOVING_RGB = (0, 255, 0)


@njit(nogil=True, cache=True)
def _top_points(row, col, z, size):  # pragma: no cover - compiled
    """Per pixel of a ``size`` x ``size`` grid the index of its highest point (-1: none); of points at the same
    height the later one. What drawing the points lowest first gives (later writes win), without sorting.

    Parameters
    ----------
    row, col : (n,) int64
        Pixel of each point (those outside the grid are skipped).
    z : (n,) float64
        Height, metres.
    size : int

    Returns
    -------
    (size * size,) int64
    """
    top = np.full(size * size, -1, np.int64)
    for i in range(z.shape[0]):
        r, c = row[i], col[i]
        if r < 0 or r >= size or c < 0 or c >= size:
            continue
        p = r * size + c
        if top[p] < 0 or z[i] >= z[top[p]]:
            top[p] = i
    return top


def bev_image(xyz: np.ndarray, cls: np.ndarray, extent_m: float = 80.0, res_m: float = 0.1,
              legend: bool = True, title: str | None = None, moving: np.ndarray | None = None) -> Image.Image:
    """Render the scan.

    Parameters
    ----------
    xyz : (n, 3) float
        Sensor frame, metres.
    cls : (n,) uint8
        Native class ids (colours from ``class_table().colors``).
    extent_m : float
        Side of the square shown, centred on the sensor.
    res_m : float
        Metres per pixel.
    moving : (n,) bool or uint8, optional
        Points on a moving actor (``points["moving"]``), drawn in :data:`MOVING_RGB` above the rest.

    Returns
    -------
    PIL.Image.Image
        RGB, ``extent_m / res_m`` pixels square plus a legend strip on the right.
    """
    table = class_table()
    size = int(round(extent_m / res_m))
    xyz = np.asarray(xyz, np.float64)
    cls = np.asarray(cls)
    row = np.floor((extent_m / 2 - xyz[:, 0]) / res_m).astype(np.int64)
    col = np.floor((extent_m / 2 - xyz[:, 1]) / res_m).astype(np.int64)
    keep = (row >= 0) & (row < size) & (col >= 0) & (col < size)
    moving = np.zeros(len(cls), bool) if moving is None else np.asarray(moving, bool)
    top = _top_points(row, col, np.ascontiguousarray(xyz[:, 2]), size)  # the highest point covers the rest
    seen = np.flatnonzero(top >= 0)
    img = np.zeros((size, size, 3), np.uint8)
    img.reshape(-1, 3)[seen] = table.colors[cls[top[seen]]]
    mr, mc = row[keep & moving], col[keep & moving]  # painted over everything
    for dr in (-1, 0, 1):  # 3x3 dots: a mover stands out of the terrain and vegetation greens
        for dc in (-1, 0, 1):
            img[np.clip(mr + dr, 0, size - 1), np.clip(mc + dc, 0, size - 1)] = MOVING_RGB
    mid = size // 2
    img[mid, mid - 4: mid + 5] = 255
    img[mid - 4: mid + 5, mid] = 255
    canvas = Image.fromarray(img, "RGB")
    if not legend:
        return canvas
    present = np.unique(cls)
    strip = 170
    out = Image.new("RGB", (size + strip, size), (24, 24, 24))
    out.paste(canvas, (0, 0))
    draw = ImageDraw.Draw(out)
    y = 8
    if title:
        draw.text((size + 8, y), title, fill=(255, 255, 255))
        y += 18
    draw.text((size + 8, y), f"{extent_m:.0f} m, {res_m:g} m/px", fill=(200, 200, 200))
    y += 14
    draw.text((size + 8, y), "x fwd = up, y left = left", fill=(200, 200, 200))
    y += 20
    counts = np.bincount(cls.astype(np.int64), minlength=len(table))
    for cid in present:
        draw.rectangle((size + 8, y, size + 22, y + 12), fill=tuple(int(v) for v in table.colors[cid]),
                       outline=(255, 255, 255))
        draw.text((size + 28, y), f"{table.names[cid]} ({counts[cid]})", fill=(255, 255, 255))
        y += 18
    if moving.any():
        draw.rectangle((size + 8, y, size + 22, y + 12), fill=MOVING_RGB, outline=(255, 255, 255))
        draw.text((size + 28, y), f"moving, any class ({int(moving.sum())})", fill=(255, 255, 255))
    return out


def write_bev(path: str | Path, xyz: np.ndarray, cls: np.ndarray, **kwargs) -> None:
    """Write :func:`bev_image` as a PNG atomically (keyword arguments as there)."""
    img = bev_image(xyz, cls, **kwargs)
    with atomic_path(path) as tmp:
        img.save(tmp, format="PNG", compress_level=3)  # 1.25x faster than the default (6), files ~20 % larger
