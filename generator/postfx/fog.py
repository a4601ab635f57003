"""Fog in post-processing from the depth pass (Koschmieder's law).

Every pixel is attenuated along its own ray and filled with scattered light::

    I = J * t + A * (1 - t),    t = exp(-beta * d),    beta = 3.912 / V

with ``J`` the rendered (fog-free) linear radiance, ``d`` the depth pass (metres along the
ray, ``inf`` for sky, so the sky becomes pure airlight), ``V`` the meteorological visibility
and ``A`` the airlight, the radiance of an infinitely deep column of fog.

The airlight follows the time of day (:func:`airlight_for`): a bright, slightly bluish grey
by day, a dark blue-grey at night, and at night it is lifted near lamps: the light a bright
emitter loses on its way to the camera, ``J (1 - t)``, is scattered (mostly forward) into a
halo, modelled as a blurred map of that lost light (a sum of Gaussians, narrow to wide)
added to the airlight. Thin fog and near lamps give faint halos, dense fog and far lamps
bright ones. Fog only changes RGB; masks and depth are never touched.

The halo is built with the filters of :mod:`generator.postfx.filters` (blurs on
block-averaged copies, so wide halos cost about as much as narrow ones).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from generator.postfx.filters import EMITTER_CLIP, blur_sum, emitter_mask
from generator.weather import KOSCHMIEDER, LIT_TIMES

#: Day airlight, linear RGB. A preview render of the test town by day (sun 25..65 deg) has
#: road at 0.13, sidewalk 0.6, white paint 0.9 and clear sky 0.7..1.9 (median 1.0) luminance.
#: Fog scatters sun and sky light like a bright diffuse surface but blocks the direct sun:
#: a light grey between a mid-grey sidewalk and white paint, below the clear sky, a touch blue.
DAY_AIRLIGHT = (0.68, 0.71, 0.76)
#: Night airlight, linear RGB: a dark blue-grey (city sky glow scattered by the fog).
NIGHT_AIRLIGHT = (0.010, 0.012, 0.018)
#: Dusk: sky light scattered like by day (the caller scales the image by the scene's light level,
#: :func:`generator.weather.light_level`), with lamp halos like at night.
BASE_AIRLIGHT = {"day": DAY_AIRLIGHT, "dusk": DAY_AIRLIGHT, "night": NIGHT_AIRLIGHT}
#: Times of day whose lamps are lit (halos in fog).

#: Halo widths as a fraction of the image width, and the share of the halo in each.
HALO_WIDTHS = (0.006, 0.02, 0.06)
HALO_WEIGHTS = (0.3, 0.4, 0.3)
#: Halo gain: the light a lamp loses on its way to the camera, ``J (1 - t)``, is scattered
#: mostly forward, into a halo around it; the gain is the share that stays in the halo.
HALO_GAIN = 1.0



def beta_from_visibility(visibility_m: float) -> float:
    """Extinction coefficient (1/m) of fog with meteorological visibility ``visibility_m`` (m)."""
    if not visibility_m > 0:
        raise ValueError(f"visibility must be > 0 m, got {visibility_m}")
    return KOSCHMIEDER / float(visibility_m)


def transmission(depth: np.ndarray, beta_per_m: float) -> np.ndarray:
    """Fog transmission ``t = exp(-beta d)`` per pixel.

    Parameters
    ----------
    depth : (H, W) float32
        Metres along the ray; ``inf`` for sky.
    beta_per_m : float
        Extinction coefficient, >= 0.

    Returns
    -------
    (H, W) float32
        1 = no fog in front of the pixel, 0 = pure airlight (sky with any fog).
    """
    if beta_per_m < 0:
        raise ValueError(f"beta must be >= 0, got {beta_per_m}")
    if beta_per_m == 0:
        return np.ones(depth.shape, np.float32)
    d = np.nan_to_num(depth.astype(np.float32, copy=False), nan=np.inf)
    return np.exp(np.float32(-beta_per_m) * d).astype(np.float32, copy=False)


@dataclass(frozen=True)
class Airlight:
    """The airlight of one image.

    Attributes
    ----------
    base_rgb : (3,) tuple of float
        Linear RGB of the fog far from any lamp.
    glow : (H, W, 3) float32 or None
        Lamp halo added to ``base_rgb`` (night), None when there is none.
    glow_params : dict
        How the halo was made (for metadata); empty without one.
    """

    base_rgb: tuple[float, float, float]
    glow: np.ndarray | None = None
    glow_params: dict | None = None

    def field(self) -> np.ndarray:
        """The airlight per pixel: (H, W, 3) float32 with a halo, else (3,) float32."""
        base = np.asarray(self.base_rgb, np.float32)
        return base if self.glow is None else self.glow + base

    def to_dict(self) -> dict:
        """Metadata record of the airlight."""
        return {"airlight_rgb": [round(float(c), 6) for c in self.base_rgb],
                "lamp_halo": dict(self.glow_params) if self.glow_params else None}


def lamp_halo(rgb: np.ndarray, depth: np.ndarray, beta_per_m: float) -> tuple[np.ndarray, dict]:
    """Light of the bright emitters scattered by the fog into halos.

    Each emitter loses ``J (1 - t)`` of its radiance on the way to the camera; that light,
    scattered mostly forward, is spread around it by the sum of Gaussians
    (:data:`HALO_WIDTHS`, :data:`HALO_WEIGHTS`), so near lamps in thin fog get faint halos
    and far lamps in dense fog bright ones.

    Parameters
    ----------
    rgb : (H, W, 3) float32
        Linear fog-free render.
    depth : (H, W) float32
        Metres along the ray (inf = sky).
    beta_per_m : float
        Fog extinction coefficient.

    Returns
    -------
    glow : (H, W, 3) float32 or None
        Radiance to add to the airlight; None without emitters or fog.
    params : dict
        Emitter pixel count, gain and halo widths (for metadata).
    """
    h, w = depth.shape
    on = emitter_mask(rgb)
    n_emit = int(np.count_nonzero(on))
    glow = None
    if n_emit and beta_per_m > 0:
        # Only emitter pixels lose light to the halo: compute their share sparsely.
        lost = np.zeros((h, w, 3), np.float32)
        t = transmission(depth[on], beta_per_m)
        lost[on] = np.minimum(rgb[on], EMITTER_CLIP) * (HALO_GAIN * (1.0 - t))[:, None]
        glow = blur_sum(lost, [frac * w for frac in HALO_WIDTHS], HALO_WEIGHTS)
    params = {"emitter_pixels": n_emit, "gain": HALO_GAIN, "widths_px": [round(f * w, 2) for f in HALO_WIDTHS]}
    return glow, params


def airlight_for(time_of_day: str, rgb: np.ndarray | None = None, beta_per_m: float = 0.0,
                 depth: np.ndarray | None = None) -> Airlight:
    """The airlight of an image taken at ``time_of_day``.

    Parameters
    ----------
    time_of_day : {"day", "dusk", "night"}
    rgb : (H, W, 3) float32, optional
        The fog-free render; at night its lamps lift the airlight (halos).
    beta_per_m : float
        Fog extinction coefficient; 0 = no halo.
    depth : (H, W) float32, optional
        Metres along the ray; needed with ``rgb`` for the halos (how much light each lamp
        loses to the fog).

    Returns
    -------
    Airlight
    """
    try:
        base = BASE_AIRLIGHT[time_of_day]
    except KeyError:
        raise ValueError(f"unknown time of day {time_of_day!r}; known: {', '.join(BASE_AIRLIGHT)}") from None
    if time_of_day in LIT_TIMES and rgb is not None and depth is not None and beta_per_m > 0:
        glow, params = lamp_halo(rgb, depth, beta_per_m)
        return Airlight(base, glow, params)
    return Airlight(base)


def apply_fog(rgb: np.ndarray, depth: np.ndarray, beta_per_m: float, airlight) -> np.ndarray:
    """Koschmieder fog: ``I = J t + A (1 - t)``, ``t = exp(-beta d)``.

    Parameters
    ----------
    rgb : (H, W, 3) float32
        Linear fog-free radiance ``J``; not modified.
    depth : (H, W) float32
        Metres along the ray; ``inf`` = sky (becomes pure airlight).
    beta_per_m : float
        Extinction coefficient (1/m), ``3.912 / visibility``; 0 leaves the image unchanged.
    airlight : Airlight or array_like, (3,) or (H, W, 3)
        Linear RGB airlight ``A``.

    Returns
    -------
    (H, W, 3) float32
        The fogged image (a new array).
    """
    if rgb.ndim != 3 or rgb.shape[2] != 3 or depth.shape != rgb.shape[:2]:
        raise ValueError(f"rgb (H, W, 3) and depth (H, W) must match, got {rgb.shape} and {depth.shape}")
    a = airlight.field() if isinstance(airlight, Airlight) else np.asarray(airlight, np.float32)
    t = transmission(depth, beta_per_m)[..., None]
    j = rgb.astype(np.float32, copy=False)
    return (j * t + a * (np.float32(1.0) - t)).astype(np.float32, copy=False)


def fog_image(rgb: np.ndarray, depth: np.ndarray, visibility_m: float, time_of_day: str) -> tuple[np.ndarray, dict]:
    """Fog an image for metadata-carrying callers: the fogged RGB and the parameters used.

    Parameters
    ----------
    rgb : (H, W, 3) float32 linear
    depth : (H, W) float32, metres along the ray (inf = sky)
    visibility_m : float
        Meteorological visibility (m).
    time_of_day : {"day", "dusk", "night"}

    Returns
    -------
    rgb : (H, W, 3) float32
    params : dict
        ``model``, ``visibility_m``, ``beta_per_m``, ``airlight_rgb``, ``lamp_halo``.
    """
    beta = beta_from_visibility(visibility_m)
    air = airlight_for(time_of_day, rgb, beta, depth)
    out = apply_fog(rgb, depth, beta, air)
    return out, {"model": "koschmieder", "visibility_m": float(visibility_m), "beta_per_m": beta, **air.to_dict()}
