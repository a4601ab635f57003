"""The camera response curve: linear sensor signal -> 8-bit sRGB (the camera model's last step).

A filmic S-curve (Lottes 2016, "Advanced techniques and optimization of HDR color
pipelines") maps the exposed linear signal ``x`` to display-linear ``y`` in [0, 1]::

    y = x^a / (x^(a d) b + c)        b, c such that  y(mid_in) = mid_out,  y(white) = 1

``a`` is the contrast (> 1: darker shadows, an S in log space), ``d`` the shoulder (< 1: a
softer roll-off of the highlights), ``white`` the signal that reaches white (above it:
clipped), ``mid_in -> mid_out`` pins mid grey. Then the sRGB transfer function and 8 bits.

The curve is applied through a table over every float16 value: the EXR holds half floats and
the camera model rounds its output to them, so the 8-bit images come out the same from memory
as from the files, and a 1920x1080 image costs one gather instead of three powers per pixel.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

#: Ranges of the per-image draws (uniform).
CRF_RANGES = {
    "contrast": (1.15, 1.45),
    "shoulder": (0.96, 0.995),
    "white": (6.0, 14.0),
    "mid_out": (0.15, 0.20),
}
MID_IN = 0.18


def draw_crf(rng: np.random.Generator) -> dict:
    """The response curve of one image: ``contrast``, ``shoulder``, ``white``, ``mid_in``, ``mid_out``."""
    out = {k: float(rng.uniform(*CRF_RANGES[k])) for k in ("contrast", "shoulder", "white", "mid_out")}
    return {**out, "mid_in": MID_IN}


def _coefficients(a: float, d: float, white: float, mid_in: float, mid_out: float) -> tuple[float, float]:
    ma, mad = mid_in**a, mid_in ** (a * d)
    wa, wad = white**a, white ** (a * d)
    den = (wad - mad) * mid_out
    b = (-ma + wa * mid_out) / den
    c = (wad * ma - wa * mad * mid_out) / den
    if not (b > 0 and c > 0):
        raise ValueError(
            f"response curve without a monotone solution: a={a} d={d} white={white} mid={mid_in}->{mid_out}"
        )
    return b, c


def curve(x: np.ndarray, crf: dict) -> np.ndarray:
    """Display-linear [0, 1] of linear signal ``x`` (float64) under the response curve ``crf``."""
    a, d, white = float(crf["contrast"]), float(crf["shoulder"]), float(crf["white"])
    b, c = _coefficients(a, d, white, float(crf["mid_in"]), float(crf["mid_out"]))
    x = np.clip(np.nan_to_num(np.asarray(x, np.float64), nan=0.0, posinf=white), 0.0, white)
    xa = x**a
    return np.clip(xa / (xa**d * b + c), 0.0, 1.0)


def srgb_encode(y: np.ndarray) -> np.ndarray:
    """The sRGB transfer function of display-linear ``y`` in [0, 1]."""
    return np.where(y <= 0.0031308, 12.92 * y, 1.055 * np.power(y, 1 / 2.4) - 0.055)


@lru_cache(maxsize=64)
def _table(key: tuple) -> np.ndarray:
    crf = dict(key)
    halves = np.arange(65536, dtype=np.uint16).view(np.float16).astype(np.float64)
    y = srgb_encode(curve(halves, crf))
    return (np.clip(y, 0, 1) * 255 + 0.5).astype(np.uint8)


def crf_8bit(rgb: np.ndarray, crf: dict) -> np.ndarray:
    """(H, W, 3) linear signal -> (H, W, 3) uint8 sRGB under the response curve ``crf``.

    The signal is read as float16 (exact for the camera model's output and for EXR RGB).
    """
    key = tuple(sorted((k, float(crf[k])) for k in ("contrast", "shoulder", "white", "mid_in", "mid_out")))
    codes = np.ascontiguousarray(rgb, np.float32).astype(np.float16).view(np.uint16)
    return _table(key)[codes]
