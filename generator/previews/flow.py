"""Optical flow as a picture: the Middlebury colour coding (Baker et al., IJCV 2011).

Hue is the flow's direction, saturation its length relative to ``max_px`` (white: no motion; a
flow longer than ``max_px`` is drawn at 75 % brightness); pixels without a flow are black. The
wheel has the paper's 55 hues: red-yellow 15, yellow-green 6, green-cyan 4, cyan-blue 11,
blue-magenta 13, magenta-red 6.
"""

from __future__ import annotations

import numpy as np

_SEGMENTS = ((15, (255, 0, 0), (255, 255, 0)), (6, (255, 255, 0), (0, 255, 0)), (4, (0, 255, 0), (0, 255, 255)),
             (11, (0, 255, 255), (0, 0, 255)), (13, (0, 0, 255), (255, 0, 255)), (6, (255, 0, 255), (255, 0, 0)))


def color_wheel() -> np.ndarray:
    """(55, 3) float64 RGB in [0, 1]: the wheel's hues in order."""
    rows = []
    for n, a, b in _SEGMENTS:
        f = np.arange(n)[:, None] / n
        rows.append((1 - f) * np.asarray(a, float) + f * np.asarray(b, float))
    return np.concatenate(rows) / 255.0


def flow_colors(uv: np.ndarray, valid: np.ndarray | None = None, max_px: float | None = None) -> np.ndarray:
    """(H, W, 3) uint8 colour image of a flow field.

    Parameters
    ----------
    uv : (H, W, 2) float
        Flow in pixels (u right, v down).
    valid : (H, W) bool, optional
        Pixels with a flow (others black).
    max_px : float, optional
        Length drawn fully saturated (default: the 99th percentile of the valid lengths).
    """
    u, v = np.asarray(uv[..., 0], np.float64), np.asarray(uv[..., 1], np.float64)
    ok = np.ones(u.shape, bool) if valid is None else np.asarray(valid, bool)
    ok &= np.isfinite(u) & np.isfinite(v)
    mag = np.hypot(u, v)
    if max_px is None:
        max_px = float(np.percentile(mag[ok], 99)) if ok.any() else 1.0
    rad = mag / max(max_px, 1e-9)
    wheel = color_wheel()
    n = len(wheel)
    fk = (np.arctan2(-v, -u) / np.pi + 1) / 2 * (n - 1)
    k0 = np.floor(fk).astype(int) % n
    k1 = (k0 + 1) % n
    f = (fk - np.floor(fk))[..., None]
    col = (1 - f) * wheel[k0] + f * wheel[k1]
    inside = (rad <= 1)[..., None]
    col = np.where(inside, 1 - np.minimum(rad, 1)[..., None] * (1 - col), col * 0.75)
    out = (col * 255).round().astype(np.uint8)
    out[~ok] = 0
    return out


def wheel_legend(size: int = 96) -> np.ndarray:
    """(size, size, 3) uint8: the colour coding of flows up to the disc's radius."""
    c = (np.arange(size) + 0.5 - size / 2) / (size / 2)
    u, v = np.meshgrid(c, c)
    return flow_colors(np.stack([u, v], -1), np.hypot(u, v) <= 1, 1.0)
