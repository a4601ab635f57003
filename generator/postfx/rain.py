"""Rain in post-processing: falling-drop streaks and drops on the lens.

**Streaks.** Drops are scattered in front of the camera at distances ``d`` (log-uniform in
``[NEAR_M, FAR_M]``, so every distance band shows streaks). A drop of diameter ``D`` (drawn
from the Marshall-Palmer spectrum of the rain rate, whose median grows as ``R^0.21``) falls at
its terminal velocity ``v(D)`` (Atlas et al. 1973) and during the exposure traces a streak of
``f v T / d`` pixels, slanted by a wind angle shared by the image. Near streaks are long, wide
(out of focus) and faint per pixel; far ones short, thin and dim. A streak at distance ``d``
is only drawn over pixels whose scene depth is larger than ``d`` (occlusion by nearer
geometry). Streaks are splatted with bilinear weights (one ``bincount``), blurred per depth
layer and composited over the image with the radiance a drop refracts: the scene's local
brightness (plus, at night, the light of nearby lamps), so night streaks are dark except
near lamps.

**Lens drops.** A few round or oval drops sit on the lens, more with more rain: each shows an
inverted, minified, defocused view of its surroundings (a water drop is a strong lens),
with a soft edge and a darker rim.

Everything random comes from the ``rng`` argument; rain only changes RGB.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import ndimage

from generator.postfx.filters import block_mean, emitter_map, gaussian, upsample
from generator.weather import LIT_TIMES

#: Nearest and farthest drop distance drawn (m).
NEAR_M, FAR_M = 0.5, 25.0
#: Depth layers (m) blurred separately, and their blur at 640 px width (defocus of near drops).
LAYER_EDGES_M = (1.5, 4.0, 10.0)
LAYER_SIGMA_PX = (1.3, 0.8, 0.6, 0.5)
#: Exposure time (s) of the camera by time of day (longer at night): streak length = f v T / d.
EXPOSURE_S = {"day": 1.0 / 60.0, "dusk": 1.0 / 30.0, "night": 1.0 / 30.0}
#: Streaks per image at 1 mm/h and the exponent of their growth with the rain rate.
STREAKS_AT_1MMH = 300
STREAK_RATE_EXP = 0.75
#: Peak opacity of a 2 mm drop's streak before defocus; streak radiance = GAIN x local brightness.
STREAK_ALPHA = 0.5
STREAK_GAIN = {"day": 1.5, "dusk": 1.5, "night": 1.5}
#: Share of the whole view's mean radiance in a streak: by day drops refract the bright sky;
#: at night only the light near a drop counts (streaks are dark except near lamps).
ENV_SHARE = {"day": 0.5, "dusk": 0.25, "night": 0.0}
#: Lamp light a drop catches at night (x blurred emitter map).
LAMP_GLINT = 0.12
#: Mean lens drops at 10 mm/h (Poisson), radius range as a fraction of the image width.
LENS_DROPS_AT_10MMH = 4.0
LENS_RADIUS = (0.012, 0.045)
SAMPLE_STEP_PX = 0.5


def terminal_velocity(diameter_mm: np.ndarray) -> np.ndarray:
    """Fall speed (m/s) of raindrops of diameter ``diameter_mm`` (Atlas et al. 1973)."""
    return np.maximum(9.65 - 10.3 * np.exp(-0.6 * diameter_mm), 0.5)


def drop_diameters(rate_mmh: float, n: int, rng: np.random.Generator) -> np.ndarray:
    """(n,) float64 drop diameters (mm) from the Marshall-Palmer spectrum, 0.8..6 mm.

    ``N(D) ~ exp(-L D)`` with ``L = 4.1 R^-0.21`` per mm; drops under 0.8 mm are too small to
    leave a visible streak and are left out (the exponential tail above 0.8 mm is again
    exponential with the same ``L``).
    """
    lam = 4.1 * max(rate_mmh, 0.1) ** -0.21
    return np.minimum(0.8 + rng.exponential(1.0 / lam, n), 6.0)


def _splat(x, y, w, layer, n_layers, h, wd) -> np.ndarray:
    """Bilinear splat of weighted points into ``n_layers`` (H, W) float32 maps."""
    x0 = np.floor(x).astype(np.intp)
    y0 = np.floor(y).astype(np.intp)
    fx, fy = x - x0, y - y0
    idx, wts = [], []
    for dy, dx, ww in ((0, 0, (1 - fx) * (1 - fy)), (0, 1, fx * (1 - fy)), (1, 0, (1 - fx) * fy), (1, 1, fx * fy)):
        yy, xx = y0 + dy, x0 + dx
        ok = (yy >= 0) & (yy < h) & (xx >= 0) & (xx < wd)
        idx.append((layer[ok] * h + yy[ok]) * wd + xx[ok])
        wts.append((w * ww)[ok])
    acc = np.bincount(np.concatenate(idx), np.concatenate(wts), minlength=n_layers * h * wd)
    return acc.astype(np.float32).reshape(n_layers, h, wd)


def streak_alpha(depth: np.ndarray, rate_mmh: float, rng: np.random.Generator, focal_px: float,
                 exposure_s: float) -> tuple[np.ndarray, dict]:
    """Opacity map of the rain streaks.

    Parameters
    ----------
    depth : (H, W) float32
        Scene depth along the ray (m); occludes streaks behind geometry.
    rate_mmh : float
        Rain rate.
    focal_px : float
        Focal length in pixels.
    exposure_s : float
        Exposure time; streak length = focal_px * v * exposure_s / d.

    Returns
    -------
    alpha : (H, W) float32 in [0, 0.9]
    params : dict
    """
    h, w = depth.shape
    scale = w / 640.0
    n = int(rng.poisson(STREAKS_AT_1MMH * max(rate_mmh, 0.0) ** STREAK_RATE_EXP))
    wind = float(np.clip(rng.normal(0.0, 12.0), -35.0, 35.0))
    dist = np.exp(rng.uniform(math.log(NEAR_M), math.log(FAR_M), n))
    diam = drop_diameters(rate_mmh, n, rng)
    length = np.clip(focal_px * terminal_velocity(diam) * exposure_s / dist, 1.5 * scale, 0.4 * h)
    angle = np.radians(wind + rng.normal(0.0, 2.5, n))
    cx, cy = rng.uniform(0, w, n), rng.uniform(0, h, n)
    width = np.maximum(diam * 1e-3 * focal_px / dist, 1.0)  # drop image width, px (>= 1: splat footprint)
    alpha = STREAK_ALPHA * np.sqrt(diam / 2.0) * rng.uniform(0.5, 1.0, n) * np.minimum(width, 3.0)

    steps = np.ceil(length / SAMPLE_STEP_PX).astype(np.intp) + 1
    first = np.repeat(np.cumsum(steps) - steps, steps)
    which = np.repeat(np.arange(n), steps)
    s = (np.arange(which.size) - first) / np.maximum(steps[which] - 1, 1)  # 0..1 along the streak
    taper = np.minimum(1.0, 5.0 * np.minimum(s, 1.0 - s) + 0.2)
    off = (s - 0.5) * length[which]
    x = cx[which] + off * np.sin(angle[which])
    y = cy[which] + off * np.cos(angle[which])
    wt = alpha[which] * taper * (length[which] / np.maximum(steps[which] - 1, 1))
    # Occlusion: keep samples in front of the scene.
    inside = (x >= 0) & (x < w) & (y >= 0) & (y < h)
    xi = np.clip(x.astype(np.intp), 0, w - 1)
    yi = np.clip(y.astype(np.intp), 0, h - 1)
    visible = inside & (depth[yi, xi] > dist[which])
    layer = np.searchsorted(np.asarray(LAYER_EDGES_M), dist)[which]
    maps = _splat(x[visible], y[visible], wt[visible], layer[visible], len(LAYER_SIGMA_PX), h, w)
    keep = np.ones((h, w), np.float32)
    for m, sigma in zip(maps, LAYER_SIGMA_PX, strict=False):
        keep *= 1.0 - np.clip(ndimage.gaussian_filter(m, sigma * scale, truncate=3.0), 0.0, 1.0)
    params = {"streaks": n, "wind_deg": round(wind, 3), "exposure_s": round(exposure_s, 6),
              "median_drop_mm": round(float(np.median(diam)), 3) if n else None}
    return np.minimum(1.0 - keep, 0.9).astype(np.float32), params


def streak_radiance(rgb: np.ndarray, time_of_day: str) -> np.ndarray:
    """(H, W, 3) float32 radiance of a streak.

    A drop refracts light from a wide cone around it (Garg & Nayar 2007), so by day its
    radiance is a mix of the local scene brightness and the mean of the whole view (sky
    included), a little desaturated; at night only local light counts, and the lamps'
    light adds glints near them. All terms are linear in the image, so one blur serves.
    """
    h, w = rgb.shape[:2]
    sigma = 0.04 * w
    f = max(1, int(sigma / 3.0))  # the radiance is smooth: build it on a block-averaged grid
    src = block_mean(np.minimum(rgb, 1.0), f)  # lamps enter through the glint term
    src = 0.6 * src + 0.4 * src.mean(-1, keepdims=True)
    if time_of_day in LIT_TIMES:  # lamps are lit at dusk and night
        src += np.float32(LAMP_GLINT / STREAK_GAIN[time_of_day]) * block_mean(emitter_map(rgb), f)
    share = ENV_SHARE[time_of_day]
    small = STREAK_GAIN[time_of_day] * (
        (1.0 - share) * gaussian(src, sigma / f) + share * src.mean((0, 1), keepdims=True)
    )
    return upsample(small.astype(np.float32), f, h, w)


def lens_drops(img: np.ndarray, rate_mmh: float, rng: np.random.Generator) -> tuple[np.ndarray, int]:
    """Composite drops on the lens over ``img`` ((H, W, 3) float32, not modified); returns (image, count)."""
    h, w = img.shape[:2]
    n = int(rng.poisson(LENS_DROPS_AT_10MMH * math.sqrt(max(rate_mmh, 0.0) / 10.0)))
    if n == 0:
        return img, 0
    f = max(1, int(0.008 * w / 2.0))
    small = ndimage.gaussian_filter(block_mean(img, f), (2.0, 2.0, 0), mode="nearest")  # defocused view
    out = img.copy()
    for _ in range(n):  # a handful of drops; each is vectorised over its bounding box
        r = w * rng.uniform(*LENS_RADIUS)
        aspect, rot = rng.uniform(0.65, 1.0), rng.uniform(0, math.pi)
        cx, cy = rng.uniform(0, w), rng.uniform(0, h)
        mag = rng.uniform(1.8, 3.0)  # the drop shows a region mag x its size, inverted
        x0, x1 = int(max(cx - r, 0)), int(min(cx + r + 1, w))
        y0, y1 = int(max(cy - r, 0)), int(min(cy + r + 1, h))
        if x1 <= x0 or y1 <= y0:
            continue
        yy, xx = np.mgrid[y0:y1, x0:x1].astype(np.float32)
        dx, dy = xx - cx, yy - cy
        u = (dx * math.cos(rot) + dy * math.sin(rot)) / r
        v = (-dx * math.sin(rot) + dy * math.cos(rot)) / (r * aspect)
        rho = np.sqrt(u * u + v * v)
        a = np.clip((1.0 - rho) / 0.35, 0.0, 1.0)
        a = a * a * (3 - 2 * a)
        sx = (cx - dx * mag + 0.5) / f - 0.5  # full-res pixel -> block grid
        sy = (cy - dy * mag + 0.5) / f - 0.5
        coords = np.stack([np.clip(sy, 0, small.shape[0] - 1), np.clip(sx, 0, small.shape[1] - 1)])
        view = np.stack([ndimage.map_coordinates(small[..., c], coords, order=1) for c in range(3)], -1)
        rim = np.exp(-(((rho - 0.75) / 0.15) ** 2))
        view *= (1.0 - 0.15 * rim)[..., None]
        patch = out[y0:y1, x0:x1]
        out[y0:y1, x0:x1] = patch * (1 - a[..., None]) + view * a[..., None]
    return out, n


def rain_image(rgb: np.ndarray, depth: np.ndarray, rate_mmh: float, rng: np.random.Generator, time_of_day: str,
               k: np.ndarray | None = None) -> tuple[np.ndarray, dict]:
    """Rain streaks and lens drops over an image, and the parameters drawn (for metadata).

    Parameters
    ----------
    rgb : (H, W, 3) float32
        Linear radiance; not modified.
    depth : (H, W) float32
        Metres along the ray, inf = sky.
    rate_mmh : float
        Rain rate (mm/h); more rain = more, longer streaks and more lens drops.
    rng : numpy.random.Generator
        The image's rain stream (``stream(seed, "frame", k, "rain", time, kind)``).
    time_of_day : {"day", "dusk", "night"}
    k : (3, 3) float64, optional
        Intrinsics; the focal length sets streak lengths (default: 90 deg horizontal FOV).

    Returns
    -------
    rgb : (H, W, 3) float32
        A new array.
    params : dict
        ``rate_mmh``, ``streaks``, ``wind_deg``, ``exposure_s``, ``median_drop_mm``, ``lens_drops``.
    """
    if rgb.ndim != 3 or rgb.shape[2] != 3 or depth.shape != rgb.shape[:2]:
        raise ValueError(f"rgb (H, W, 3) and depth (H, W) must match, got {rgb.shape} and {depth.shape}")
    if time_of_day not in STREAK_GAIN:
        raise ValueError(f"unknown time of day {time_of_day!r}; known: {', '.join(STREAK_GAIN)}")
    if rate_mmh < 0:
        raise ValueError(f"rain rate must be >= 0 mm/h, got {rate_mmh}")
    img = rgb.astype(np.float32, copy=False)
    focal = float(k[0, 0]) if k is not None else rgb.shape[1] / 2.0
    alpha, params = streak_alpha(depth, rate_mmh, rng, focal, EXPOSURE_S[time_of_day])
    a = alpha[..., None]
    out = img * (1.0 - a) + streak_radiance(img, time_of_day) * a
    out, n_drops = lens_drops(out, rate_mmh, rng)
    return out.astype(np.float32, copy=False), {"rate_mmh": float(rate_mmh), **params, "lens_drops": n_drops}


def apply_rain(rgb: np.ndarray, depth: np.ndarray, rate_mmh: float, rng: np.random.Generator, time_of_day: str,
               k: np.ndarray | None = None) -> np.ndarray:
    """Rain streaks and lens drops over an image; see :func:`rain_image` (which also returns the parameters)."""
    return rain_image(rgb, depth, rate_mmh, rng, time_of_day, k)[0]
