"""LiDAR weather: the scan of frame ``k`` sees the weather draw its camera images see.

The kind is ``generator.weather.lidar_combination(k)`` and the parameters are
``generator.weather.draw_weather(spec, k, kind)`` (visibility, rain rate, wetness), so a
foggy image and its scan share the same visibility. Per point (constants in ``weather.yaml``):

* **extinction** ``alpha = alpha_fog + alpha_rain`` (1/m): ``alpha_fog`` is the image's
  ``beta = 3.912 / V`` (wavelength independent for V < 0.5 km, Kim et al. 2001);
  ``alpha_rain = 0.01 R^0.6`` per **km** (R in mm/h) = ``0.01 R^0.6 / 1000`` per metre;
* **detection**: the normalised received power (``intensity.received_power``:
  ``rho * cos * (R0/R)^2``, retroreflective lobe included) times ``exp(-2 alpha R)`` (and the
  wet-ground factor) must reach ``spec.lidar.weather.detection_threshold``, else the point is lost;
  the same test runs in clear weather (alpha = 0), where the default threshold keeps
  everything but the faintest grazing returns. With the physical sensor
  (:mod:`generator.lidar.returns`) the scanner has already detected every return against its own
  threshold with this ``alpha`` (each point's ``power``): only the wet-ground factor can still push
  a return below that threshold;
* **intensity**: every remission is multiplied by ``exp(-2 alpha R)`` (and the wet factor);
* **fog soft returns**: with probability ``min(0.02, 0.1 m * beta)`` a ray reports the
  fog itself at ``min_range + Gamma(2, 1.5 m)`` (only when that is in front of its hard
  target), labelled unlabeled (0), instance 0, faint remission;
* **rain range noise**: ``r += N(0, sigma)``, ``sigma = 0.02 r (1 - exp(-R))^2`` (r in m, R in mm/h),
  along the beam;
* **wet ground** (road, parking, sidewalk/curb, other-ground, markings): power and remission
  times ``1 - wetness (1 - 0.4)``, and lost with extra probability ``wetness * 0.2 * (1 - cos)``.

Randomness: the generator passed in (``stream(seed, "frame", k, "lidar_weather")``).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generator.labels import class_table
from generator.remission.models import received_power, semantic_ids
from generator.safeload import load_package_yaml
from generator.weather import Weather, draw_weather, lidar_combination

CONFIG_FILE = Path(__file__).resolve().parent / "weather.yaml"


@functools.cache
def weather_config() -> dict:
    """``weather.yaml`` as a dict, with ``wet.semantickitti_ids`` (paved ground) from the class table."""
    cfg = load_package_yaml(CONFIG_FILE.read_text(encoding="utf-8"))
    cfg["wet"] = {"semantickitti_ids": list(class_table().wet_ground_raw_ids), **cfg["wet"]}
    return cfg


@dataclass(frozen=True)
class LidarWeatherParams:
    """How the LiDAR weather is applied.

    Attributes
    ----------
    detection_threshold : float
        Minimum normalised received power (1 = reflectivity-1 Lambertian target at 10 m, normal incidence, clear air).
    min_range_m : float
        The sensor's minimum range (soft returns start there).
    """

    detection_threshold: float = 1e-5
    min_range_m: float = 0.9
    #: the points carry the physical sensor's received power (``power``, atmosphere included) and were
    #: already detected against ``detection_threshold``: the weather only adds the wet-ground loss
    received: bool = False


def enabled_for_spec(spec, default: bool) -> bool:
    """``spec.lidar.weather.enabled``, or ``default`` when it is null (auto)."""
    on = spec.lidar.weather.enabled
    return default if on is None else bool(on)


def frame_weather(spec, frame_index: int) -> tuple[str, Weather]:
    """(time of day, weather draw) the scan of ``frame_index`` shares with its images."""
    tod, kind = lidar_combination(frame_index, spec.weather.times_of_day)
    return tod, draw_weather(spec, frame_index, kind)


def extinction_per_m(weather: Weather) -> tuple[float, float]:
    """(alpha_fog, alpha_rain) in 1/m for a weather draw."""
    rain = weather_config()["rain"]
    fog = float(weather.beta_per_m or 0.0)
    rate = float(weather.rain_rate_mmh or 0.0)
    return fog, rain["alpha_coeff"] * rate ** rain["alpha_exponent"] / rain["alpha_per_unit_m"] if rate > 0 else 0.0


def rain_range_sigma(r: np.ndarray, rain_rate_mmh: float) -> np.ndarray:
    """(n,) range noise standard deviation, metres: ``0.02 r (1 - exp(-R))^2``."""
    return (
        weather_config()["rain"]["range_noise_coeff"] * np.asarray(r, np.float64) * (1.0 - np.exp(-rain_rate_mmh)) ** 2
    )


def apply_lidar_weather(points: np.ndarray, remission: np.ndarray, weather: Weather, params: LidarWeatherParams,
                        rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, dict]:
    """Apply one weather draw to a scan.

    Parameters
    ----------
    points : (n,) structured
        Needs ``x, y, z, range`` (sensor frame, metres), ``cos_incidence`` and ``material``/class
        fields (see :func:`generator.remission.models.received_power`); native scans also get
        ``class``, ``instance``, ``material`` reset on soft returns.
    remission : (n,) float32
    weather : generator.weather.Weather
    params : LidarWeatherParams
    rng : numpy.random.Generator

    Returns
    -------
    points : (m,) same dtype
        Detected points (order kept) with rain-noised ranges and fog soft returns.
    remission : (m,) float32
    info : dict
        The weather, the extinction used and what happened (counts).
    """
    cfg = weather_config()
    n = len(points)
    a_fog, a_rain = extinction_per_m(weather)
    alpha = a_fog + a_rain
    r = points["range"].astype(np.float64)
    power = points["power"].astype(np.float64) if params.received else received_power(points, alpha)
    rem = remission.astype(np.float64) * np.exp(-2.0 * alpha * r)
    lost_wet = np.zeros(n, bool)
    wet_pts = 0
    if weather.wetness > 0:
        w = cfg["wet"]
        wet = np.isin(semantic_ids(points), np.array(w["semantickitti_ids"], np.uint16))
        wet_pts = int(wet.sum())
        factor = np.where(wet, 1.0 - weather.wetness * (1.0 - w["residual_power"]), 1.0)
        power, rem = power * factor, rem * factor
        p_loss = weather.wetness * w["dropout_max"] * (1.0 - np.clip(points["cos_incidence"], 0.0, 1.0))
        lost_wet = wet & (rng.random(n) < p_loss)
    weak = power < params.detection_threshold
    keep = ~weak & ~lost_wet
    out = points.copy()
    if weather.rain_rate_mmh:
        d = rng.normal(0.0, 1.0, n) * rain_range_sigma(r, weather.rain_rate_mmh)
        _move_along_beam(out, np.maximum(r + d, params.min_range_m))
    soft = np.zeros(n, bool)
    if weather.beta_per_m:
        f = cfg["fog"]
        p = min(f["soft_return_max"], f["soft_return_per_beta_m"] * weather.beta_per_m)
        cand = np.flatnonzero(rng.random(n) < p)
        r_soft = params.min_range_m + rng.gamma(f["soft_return_shape"], f["soft_return_scale_m"], len(cand))
        ok = r_soft < r[cand]
        cand, r_soft = cand[ok], r_soft[ok]
        soft[cand] = True
        _move_along_beam(out, r_soft, cand)
        for name in ("class", "instance", "material", "semantic", "moving"):
            if name in out.dtype.names:
                out[name][cand] = 0
        out["cos_incidence"][cand] = 0.0
        rem[cand] = rng.uniform(0.0, f["soft_return_intensity_max"], len(cand))
    keep |= soft
    info = {
        **weather.to_dict(),
        "alpha_fog_per_m": a_fog, "alpha_rain_per_m": a_rain, "alpha_per_m": alpha,
        "detection_threshold": params.detection_threshold,
        "points_in": int(n), "lost_below_threshold": int((weak & ~soft).sum()),
        "lost_wet_ground": int((lost_wet & ~weak & ~soft).sum()), "wet_ground_points": wet_pts,
        "fog_soft_returns": int(soft.sum()), "points_out": int(keep.sum()),
    }
    if weather.rain_rate_mmh:
        info["range_noise_sigma_m_at_10m"] = float(rain_range_sigma(np.array([10.0]), weather.rain_rate_mmh)[0])
    return out[keep], np.clip(rem[keep], 0.0, 1.0).astype(np.float32), info


def _move_along_beam(points: np.ndarray, new_range: np.ndarray, index: np.ndarray | None = None) -> None:
    """Set ``range`` (metres) of ``points[index]`` and slide x, y, z along the sensor-origin ray to match."""
    idx = slice(None) if index is None else index
    xyz = np.stack([points["x"][idx], points["y"][idx], points["z"][idx]], -1).astype(np.float64)
    old = points["range"][idx].astype(np.float64)
    norm = np.maximum(np.linalg.norm(xyz, axis=1), 1e-9)
    # keep the emission-point offset (range - |xyz|) so |xyz| follows the range change
    scale = np.maximum(norm + (new_range - old), 1e-3) / norm
    for i, c in enumerate("xyz"):
        points[c][idx] = (xyz[:, i] * scale).astype(np.float32)
    points["range"][idx] = new_range.astype(np.float32)
