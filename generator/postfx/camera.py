"""A camera in post: what a sensor and its lens make of the rendered (and fogged) radiance.

The render is scene radiance; a camera sees it through a lens and records it with a sensor,
then its processing maps the recording to 8 bits. In order, per image (numpy only)::

    L  (H, W, 3) linear radiance, after fog and rain (the camera sees the foggy scene)
    -> metering        exposure E from a centre-weighted log-average luminance, to a key
                       (mid grey 0.18), clamped to an EV range        (:func:`meter`)
    -> long-tail PSF   (1 - a) L + a * sum_i w_i G_sigma_i * L: glare and veil
                       around every bright source, energy conserving (:func:`psf`)
    -> lateral CA      R and B magnified about the centre by 1 +- c   (:func:`chromatic_aberration`)
    -> vignetting      1 - v rho^2, rho = distance to the centre / half diagonal
    -> exposure        s = E * (the above)
    -> sensor noise    photon (shot) noise of variance G s / Q and read noise of
                       std G r / Q, G the analog gain the exposure needs  (:func:`sensor_noise`)
    => the EXR RGB     linear, sensor-like (noisy, glared, vignetted), not clipped at the top
    -> response curve  :mod:`generator.postfx.camera_crf`, applied by the writers: the 8-bit
                       images are ``crf(EXR RGB)``

Exposure. The camera meters the scene it sees, ``m = metered * 2**radiance_scale_ev``
(:data:`RADIANCE_SCALE_EV`: the renders' night is brighter than a real night), wants
``ev = AE_STRENGTH * log2(REFERENCE_LUMINANCE / m) + ev_comp`` and gets it clamped to
``[EV_MIN, ev_max]``; the factor on the rendered radiance is
``E = KEY / REFERENCE_LUMINANCE * 2**(ev + radiance_scale_ev)``. EV 0 is the exposure of a
clear day (metered luminance :data:`REFERENCE_LUMINANCE`), so a clear day's mid grey lands on
:data:`KEY`. The camera may darken a bright scene a lot (the default town's day fog: -1.4 EV)
but brighten a dark one only up to ``ev_max`` (exposure time and gain run out): a night street,
~12 EV below a clear day in log-average, is exposed some 9-10 EV up (gain ~4..8) and stays
darker than mid grey with bright lamps, as night footage is, and a foggy day does not wash out.

Gain. Up to ``EV_BASE_GAIN`` the camera changes its exposure time at base gain (G = 1);
above it, it raises the gain, ``G = 2**(ev - EV_BASE_GAIN)``. Photo-electrons behind an output
level ``s`` are ``s Q / G``: the less light, the higher the gain, the noisier the image.

Every parameter is drawn per image from one generator (:func:`draw_params`; the image's
stream ``("frame", k, "camera_model", time_of_day, weather)``) and recorded in its metadata
(:meth:`CameraParams.to_dict`, plus what :func:`apply_camera` measured). RGB only: labels,
masks and depth never pass through here.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from generator.postfx.camera_crf import draw_crf
from generator.postfx.filters import block_mean, blur_sum, luminance

#: Mid grey: a scene metered at :data:`REFERENCE_LUMINANCE` is exposed to this linear value.
KEY = 0.18
#: Metered luminance (:func:`metered_luminance`) of a clear day: the default town's frame 3
#: at the preview preset, sun at 41 deg (EV 0).
REFERENCE_LUMINANCE = 0.16
#: Share of the metered brightness the auto-exposure compensates (< 1: a foggy day stays
#: brighter than a clear one and a dim scene dimmer, as most cameras' AE programs do).
AE_STRENGTH = 0.8
#: Lowest EV (relative to a clear day) the camera reaches: shortest exposure at base gain.
EV_MIN = -3.0
#: The EV from which the camera raises its gain (below it: longer exposure at gain 1): an
#: automotive camera's exposure time runs from ~1/4000 s on a clear day to ~1/30 s (7 EV)
#: before it raises the gain (up to another 2..4 EV, :data:`RANGES` ``ev_max``).
EV_BASE_GAIN = 7.0
#: The renders' radiance in EV relative to a physical scene of the same look, per time of day.
#: 0: the renders are lit at real ratios (a lit street at night is some 10-12 EV below a sunny
#: one, :mod:`generator.blender.night`); kept in the metadata for datasets made before, when
#: night renders were seen 3 EV darker than rendered.
RADIANCE_SCALE_EV = {"day": 0.0, "dusk": 0.0, "night": 0.0}
#: Metering grid: about this many blocks across; weights ``FLOOR + exp(-r^2 / 2 SIGMA^2)``
#: with r in units of the image width about a point a little below the centre.
METER_BLOCKS = 64
METER_SIGMA = 0.22
METER_FLOOR = 0.25
METER_CENTRE = (0.5, 0.55)
#: Long-tail PSF: Gaussian widths (fraction of the image width), equal shares: a sum of
#: log-spaced Gaussians with equal weights falls off about as 1 / r^2, a lens's glare tail.
PSF_WIDTHS = (0.004, 0.012, 0.036, 0.108)
PSF_WEIGHTS = (0.25, 0.25, 0.25, 0.25)

#: Ranges of the per-image draws (uniform unless said otherwise).
RANGES = {
    "ev_comp": (-0.3, 0.3),            # metering bias, EV (normal, sd 0.15, clipped)
    "ev_max": (9.0, 11.0),             # highest EV: longest exposure time x highest gain
    "psf_share": (0.02, 0.06),         # energy in the tail
    "vignetting": (0.10, 0.30),        # light loss at the corners
    "ca_scale": (0.0002, 0.0010),      # |lateral CA|: R magnified by 1 + c, B by 1 - c (sign drawn)
    "full_well_e": (6000.0, 20000.0),  # electrons at signal 1.0 and gain 1 (log-uniform)
    "read_noise_e": (2.0, 6.0),        # read noise, electrons
}


@dataclass(frozen=True)
class CameraParams:
    """The drawn parameters of one image's camera (see the module docstring)."""

    time_of_day: str
    radiance_scale_ev: float
    ev_comp: float
    ev_max: float
    psf_share: float
    vignetting: float
    ca_scale: float
    full_well_e: float
    read_noise_e: float
    crf: dict

    def to_dict(self) -> dict:
        """The scalar parameters (the response curve is recorded on its own)."""
        return {k: v for k, v in asdict(self).items() if k != "crf"}


def draw_params(rng: np.random.Generator, time_of_day: str) -> CameraParams:
    """Every parameter of one image's camera from its stream (a fixed number of draws, fixed order)."""
    if time_of_day not in RADIANCE_SCALE_EV:
        raise ValueError(f"unknown time of day {time_of_day!r}; known: {', '.join(RADIANCE_SCALE_EV)}")
    ev_comp = float(np.clip(rng.normal(0.0, 0.15), *RANGES["ev_comp"]))
    ev_max = float(rng.uniform(*RANGES["ev_max"]))
    psf = float(rng.uniform(*RANGES["psf_share"]))
    vig = float(rng.uniform(*RANGES["vignetting"]))
    ca = float(rng.uniform(*RANGES["ca_scale"])) * (1.0 if rng.random() < 0.5 else -1.0)
    lo, hi = RANGES["full_well_e"]
    q = float(math.exp(rng.uniform(math.log(lo), math.log(hi))))
    read = float(rng.uniform(*RANGES["read_noise_e"]))
    return CameraParams(time_of_day, RADIANCE_SCALE_EV[time_of_day], ev_comp, ev_max, psf, vig, ca, q, read,
                        draw_crf(rng))


def metering_weights(h: int, w: int) -> np.ndarray:
    """(h, w) float32 centre weights of the metering grid (see :data:`METER_SIGMA`)."""
    y = (np.arange(h, dtype=np.float32) + 0.5) / w - METER_CENTRE[1] * h / w
    x = (np.arange(w, dtype=np.float32) + 0.5) / w - METER_CENTRE[0]
    r2 = x[None, :] ** 2 + y[:, None] ** 2
    return (METER_FLOOR + np.exp(-r2 / (2 * METER_SIGMA**2))).astype(np.float32)


def metered_luminance(rgb: np.ndarray) -> float:
    """Centre-weighted log-average luminance of linear ``rgb`` (on a block-averaged grid)."""
    f = max(1, rgb.shape[1] // METER_BLOCKS)
    lum = block_mean(luminance(rgb), f)
    wts = metering_weights(*lum.shape)
    return float(np.exp((wts * np.log(np.maximum(lum, 1e-5))).sum() / wts.sum()))


def meter(rgb: np.ndarray, params: CameraParams) -> dict:
    """Auto-exposure of linear ``rgb`` (as rendered) under ``params``.

    Returns
    -------
    dict
        ``metered_luminance`` (of the render), ``ev_auto`` (wanted, with the radiance scale and
        ``ev_comp``), ``ev`` (clamped to ``[EV_MIN, ev_max]``), ``exposure`` (the factor on the
        rendered radiance, radiance scale included), ``gain`` (analog gain, >= 1).
    """
    lum = metered_luminance(rgb)
    scene = lum * 2.0**params.radiance_scale_ev
    ev_auto = AE_STRENGTH * math.log2(REFERENCE_LUMINANCE / scene) + params.ev_comp
    ev = min(max(ev_auto, EV_MIN), params.ev_max)
    return {"metered_luminance": lum, "ev_auto": ev_auto, "ev": ev,
            "exposure": KEY / REFERENCE_LUMINANCE * 2.0 ** (ev + params.radiance_scale_ev),
            "gain": max(1.0, 2.0 ** (ev - EV_BASE_GAIN))}


def psf_widths_px(width: int) -> list[float]:
    return [f * width for f in PSF_WIDTHS]


def psf(rgb: np.ndarray, share: float) -> np.ndarray:
    """The long-tail PSF: ``(1 - share) rgb + share * sum_i w_i G_i * rgb``; integrates to 1.

    The Gaussians run on block-averaged copies (:func:`generator.postfx.filters.blur_sum`), so
    the tail costs about as much as one narrow blur.
    """
    if share <= 0:
        return rgb
    tail = blur_sum(rgb, psf_widths_px(rgb.shape[1]), PSF_WEIGHTS)
    return (np.float32(1.0 - share) * rgb + np.float32(share) * tail).astype(np.float32, copy=False)


def _magnify_axis(img: np.ndarray, scale: float, axis: int) -> np.ndarray:
    """Linear resampling of ``img`` along ``axis`` magnified by ``scale`` about the centre (edges clamped)."""
    n = img.shape[axis]
    c = (n - 1) / 2.0
    src = np.clip(c + (np.arange(n) - c) / scale, 0, n - 1)
    i0 = np.floor(src).astype(np.intp)
    i1 = np.minimum(i0 + 1, n - 1)
    t = (src - i0).astype(np.float32)
    shape = [1] * img.ndim
    shape[axis] = n
    t = t.reshape(shape)
    return np.take(img, i0, axis) * (1 - t) + np.take(img, i1, axis) * t


def chromatic_aberration(rgb: np.ndarray, scale: float) -> np.ndarray:
    """Lateral CA: R magnified by ``1 + scale``, B by ``1 - scale`` about the image centre, G kept."""
    if scale == 0:
        return rgb
    out = rgb.copy()
    for ch, s in ((0, 1.0 + scale), (2, 1.0 - scale)):
        out[..., ch] = _magnify_axis(_magnify_axis(rgb[..., ch], s, 1), s, 0)
    return out


def vignetting_map(h: int, w: int, strength: float) -> np.ndarray:
    """(h, w) float32 ``1 - strength * rho^2``, rho = distance to the centre / half diagonal
    (pixel centres: the corner pixels get ``1 - strength``)."""
    half = max(0.5 * math.hypot(h - 1, w - 1), 0.5)
    y = (np.arange(h, dtype=np.float32) - (h - 1) / 2.0) / half
    x = (np.arange(w, dtype=np.float32) - (w - 1) / 2.0) / half
    return (1.0 - strength * (x[None, :] ** 2 + y[:, None] ** 2)).astype(np.float32)


def sensor_noise(signal: np.ndarray, gain: float, full_well_e: float, read_noise_e: float,
                 rng: np.random.Generator) -> np.ndarray:
    """Photon and read noise on an exposed linear signal (1.0 = ``full_well_e`` electrons at gain 1).

    Photon noise is Poisson in the electrons ``n = s Q / G``; in output units its variance is
    ``G s / Q`` (a Gaussian of that variance stands in for the Poisson draw); read noise adds
    ``(G r / Q)^2``. The output is clipped at 0 (a camera's black level).
    """
    g, q = np.float32(gain), np.float32(full_well_e)
    var = g / q * np.maximum(signal, 0) + np.float32((gain * read_noise_e / full_well_e) ** 2)
    noise = rng.standard_normal(signal.shape, dtype=np.float32)
    return np.maximum(signal + np.sqrt(var) * noise, 0).astype(np.float32, copy=False)


def apply_camera(rgb: np.ndarray, params: CameraParams, noise_rng: np.random.Generator,
                 exposure: dict | None = None) -> tuple[np.ndarray, dict]:
    """The camera model on one linear image: the EXR RGB and the metadata record.

    Parameters
    ----------
    rgb : (H, W, 3) float32
        Linear radiance (after fog and rain); not modified.
    params : CameraParams
    noise_rng : numpy.random.Generator
        Draws the sensor noise (after the parameters, from the same stream or another camera's).
    exposure : dict, optional
        A :func:`meter` result to use instead of metering ``rgb`` (a stereo pair exposes both
        cameras as the left one meters).

    Returns
    -------
    rgb : (H, W, 3) float32
        Linear, exposed, sensor-like; rounded to float16 (what the EXR holds, so that the 8-bit
        images, ``crf(EXR RGB)``, are the same from the files as from memory).
    record : dict
        The ``camera_model`` section of the image's metadata.
    """
    if rgb.ndim != 3 or rgb.shape[2] != 3:
        raise ValueError(f"rgb must be (H, W, 3), got {rgb.shape}")
    img = np.nan_to_num(rgb.astype(np.float32, copy=False), nan=0.0, posinf=0.0)
    h, w = img.shape[:2]
    expo = exposure if exposure is not None else meter(img, params)
    img = chromatic_aberration(psf(img, params.psf_share), params.ca_scale)
    img *= (np.float32(expo["exposure"]) * vignetting_map(h, w, params.vignetting))[..., None]
    img = sensor_noise(img, expo["gain"], params.full_well_e, params.read_noise_e, noise_rng)
    img = img.astype(np.float16).astype(np.float32)
    record = {
        "enabled": True,
        "order": ["meter", "psf", "chromatic_aberration", "vignetting", "exposure", "noise", "crf (8-bit only)"],
        "exr_rgb": "linear radiance x exposure after PSF, CA, vignetting and sensor noise; 8-bit = crf(EXR RGB)",
        "params": params.to_dict(),
        "exposure": dict(expo),
        "limits": {"key": KEY, "reference_luminance": REFERENCE_LUMINANCE, "ae_strength": AE_STRENGTH,
                   "ev_min": EV_MIN, "ev_base_gain": EV_BASE_GAIN},
        "psf_widths_px": psf_widths_px(w),
        "psf_weights": list(PSF_WEIGHTS),
        "crf": dict(params.crf),
    }
    return img, record
