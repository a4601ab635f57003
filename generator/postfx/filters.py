"""Image filters the weather effects share: luminance, emitter maps, fast wide blurs.

Linear RGB images are (H, W, 3) float32; masks and maps (H, W). The wide blurs work on
block-averaged copies (:func:`block_mean`, :func:`upsample`), so a wide Gaussian costs
about as much as a narrow one.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

#: Lamp halo: emitters are pixels brighter than ``EMITTER_MIN`` (linear) and ``EMITTER_RATIO``
#: times the scene's median luminance.
EMITTER_MIN = 1.0
EMITTER_RATIO = 30.0
#: Emitter radiance is clipped here before blurring (Cycles lamp cores can reach 1e3..1e4).
EMITTER_CLIP = 50.0
LUMA = np.array([0.2126, 0.7152, 0.0722], np.float32)


def luminance(rgb: np.ndarray) -> np.ndarray:
    """(H, W, 3) linear RGB -> (H, W) float32 Rec. 709 luminance."""
    return rgb.astype(np.float32, copy=False) @ LUMA


def emitter_mask(rgb: np.ndarray) -> np.ndarray:
    """(H, W) bool: the bright emitters of an image (lamps, lit windows, head lights).

    A pixel is an emitter when its luminance exceeds both :data:`EMITTER_MIN` and
    :data:`EMITTER_RATIO` times the scene's median luminance.
    """
    lum = luminance(rgb)
    threshold = max(EMITTER_MIN, EMITTER_RATIO * float(np.median(lum[::4, ::4])))  # median of a 1/16 sample
    return lum > threshold


def emitter_map(rgb: np.ndarray) -> np.ndarray:
    """The emitters' radiance, else 0.

    Parameters
    ----------
    rgb : (H, W, 3) float32 linear

    Returns
    -------
    (H, W, 3) float32
        The radiance (clipped at :data:`EMITTER_CLIP`) where :func:`emitter_mask` is set.
    """
    out = np.zeros(rgb.shape, np.float32)
    on = emitter_mask(rgb)
    out[on] = np.minimum(rgb[on], EMITTER_CLIP)
    return out


def block_mean(img: np.ndarray, f: int) -> np.ndarray:
    """Mean over ``f x f`` pixel blocks of a (H, W[, C]) image (edge-padded to whole blocks).

    Returns
    -------
    (ceil(H / f), ceil(W / f)[, C]) float32
    """
    img = img.astype(np.float32, copy=False)
    if f == 1:
        return img
    h, w = img.shape[:2]
    hp, wp = -(-h // f) * f, -(-w // f) * f
    if (hp, wp) != (h, w):
        img = np.pad(img, ((0, hp - h), (0, wp - w)) + ((0, 0),) * (img.ndim - 2), mode="edge")
    rest = img.shape[2:]
    rows = img.reshape(hp // f, f, wp * int(np.prod(rest))).sum(1)  # summing slabs: fast, contiguous
    return rows.reshape(hp // f, wp // f, f, *rest).sum(2) * np.float32(1.0 / (f * f))


def _upsample_axis(small: np.ndarray, f: int, axis: int) -> np.ndarray:
    """Linear interpolation by an integer factor ``f`` along ``axis`` (block centres -> pixel centres).

    Output pixel ``i f + p`` lies ``d_p = (p + 0.5) / f - 0.5`` blocks from block ``i``, so
    each of the ``f`` phases is one strided slice: ``(1 - |d_p|) S[i] + |d_p| S[i +- 1]``
    (edges clamped).
    """
    n = small.shape[axis]
    pad = [(0, 0)] * small.ndim
    pad[axis] = (1, 1)
    sp = np.pad(small, pad, mode="edge")
    shape = list(small.shape)
    shape[axis] = n * f
    out = np.empty(shape, np.float32)

    def cut(sl: slice) -> tuple:
        return tuple(sl if k == axis else slice(None) for k in range(small.ndim))

    for p in range(f):
        d = (p + 0.5) / f - 0.5
        s = 1 if d >= 0 else -1
        a = np.float32(abs(d))
        out[cut(slice(p, None, f))] = (1 - a) * sp[cut(slice(1, n + 1))] + a * sp[cut(slice(1 + s, n + 1 + s))]
    return out


def upsample(small: np.ndarray, f: int, h: int, w: int) -> np.ndarray:
    """Bilinear upsampling of a :func:`block_mean` image back to (h, w[, C]) float32.

    Columns first (on the short image), then rows (contiguous slabs): a few strided slice
    operations per phase instead of per-pixel gathers.
    """
    if f == 1:
        return small[:h, :w]
    return _upsample_axis(_upsample_axis(small.astype(np.float32, copy=False), f, 1), f, 0)[:h, :w]


def gaussian(img: np.ndarray, sigma: float) -> np.ndarray:
    """Gaussian blur of a (H, W[, C]) image over its two image axes (edges: nearest)."""
    return ndimage.gaussian_filter(img, (sigma, sigma) + (0,) * (img.ndim - 2), mode="nearest", truncate=3.0)


def blur_sum(img: np.ndarray, sigmas_px, weights) -> np.ndarray:
    """Weighted sum of wide Gaussian blurs of a (H, W[, C]) image, float32, same shape.

    Each blur runs on a block-averaged copy (factor ~ sigma / 3, energy preserving) and the
    wider ones are brought back to the finest copy's grid, so there is only one upsampling to
    full resolution and the cost hardly grows with sigma.
    """
    h, w = img.shape[:2]
    f0 = max(1, int(min(sigmas_px) / 3.0))
    base = block_mean(img, f0)
    acc = np.zeros_like(base)
    for sigma, weight in zip(sigmas_px, weights, strict=False):
        g = max(1, int(sigma / 3.0 / f0))
        blurred = gaussian(block_mean(base, g), sigma / (f0 * g))
        acc += np.float32(weight) * upsample(blurred, g, *base.shape[:2])
    return upsample(acc, f0, h, w)


def blur_wide(img: np.ndarray, sigma_px: float) -> np.ndarray:
    """Gaussian blur (sigma in pixels) of a (H, W[, C]) image; see :func:`blur_sum`."""
    return blur_sum(img, (sigma_px,), (1.0,))
