"""Weather and time of day: the 6 x 2 combinations of seed 003 Table II and their draws.

Every parameter comes from a named stream of the spec's seed, so the camera image of a
frame and the LiDAR scan of the same frame see the same weather:

* ``wetness`` and ``puddle_seed``: per frame (``("frame", k, "wet")``) -- the wet render of a
  frame is shared by its wet, wet_fog, rain and rain_fog variants;
* fog visibility and rain rate: per frame and kind (``("frame", k, "weather", kind)``);
* sun position and lit-window fraction: per frame and time of day.

A frame's six weather variants cost two renders per time of day: the dry render gives
``clear`` and ``fog``; the wet render gives ``wet``, ``wet_fog``, ``rain`` and ``rain_fog``.
Fog and rain are applied in post-processing from the depth pass.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from generator.rng import stream

KINDS = ("clear", "fog", "rain", "rain_fog", "wet", "wet_fog")
TIMES = ("day", "night")
#: Koschmieder: visibility V (m) = 3.912 / beta (contrast threshold 2 %).
KOSCHMIEDER = 3.912


def combinations() -> list[tuple[str, str]]:
    """The 12 (time_of_day, weather_kind) combinations, in Table II order (weather-major)."""
    return [(t, k) for k in KINDS for t in TIMES]


def lidar_combination(frame_index: int) -> tuple[str, str]:
    """The combination whose weather the LiDAR scan of a frame shares (balanced round-robin)."""
    return combinations()[frame_index % len(combinations())]


def is_wet(kind: str) -> bool:
    """True for the kinds rendered with wet shaders (wet, wet_fog, rain, rain_fog)."""
    return kind in ("rain", "rain_fog", "wet", "wet_fog")


def has_fog(kind: str) -> bool:
    return kind.endswith("fog")


def has_rain(kind: str) -> bool:
    return kind.startswith("rain")


@dataclass(frozen=True)
class Weather:
    """The weather of one image (or LiDAR scan).

    Attributes
    ----------
    kind : str
        One of :data:`KINDS`.
    wetness : float
        0 (dry) .. 1 (soaked); shader state of the render.
    puddle_seed : float
        Moves the puddle/ripple noise of the wet shaders.
    visibility_m : float or None
        Meteorological visibility of the fog; None without fog.
    beta_per_m : float or None
        Fog extinction coefficient, ``3.912 / visibility_m``.
    rain_rate_mmh : float or None
        Rain rate in mm/h; None without rain.
    """

    kind: str
    wetness: float
    puddle_seed: float
    visibility_m: float | None = None
    beta_per_m: float | None = None
    rain_rate_mmh: float | None = None

    def to_dict(self) -> dict:
        return asdict(self)


def frame_wetness(spec, frame_index: int) -> tuple[float, float]:
    """(wetness, puddle_seed) of the wet render of a frame."""
    g = stream(spec.seed, "frame", frame_index, "wet")
    return float(g.uniform(*spec.weather.wetness)), float(g.uniform(0.0, 1000.0))


def draw_weather(spec, frame_index: int, kind: str) -> Weather:
    """The weather parameters of variant ``kind`` of frame ``frame_index``."""
    if kind not in KINDS:
        raise ValueError(f"unknown weather kind {kind!r}; known: {', '.join(KINDS)}")
    wet, puddles = frame_wetness(spec, frame_index) if is_wet(kind) else (0.0, 0.0)
    g = stream(spec.seed, "frame", frame_index, "weather", kind)
    vis = beta = rate = None
    if has_fog(kind):
        lo, hi = spec.weather.fog_visibility_m
        vis = float(math.exp(g.uniform(math.log(lo), math.log(hi))))  # log-uniform: dense and light fog alike
        beta = KOSCHMIEDER / vis
    if has_rain(kind):
        rate = float(g.uniform(*spec.weather.rain_rate_mmh))
    return Weather(kind, wet, puddles, vis, beta, rate)


@dataclass(frozen=True)
class Lighting:
    """Time of day and its drawn parameters."""

    time_of_day: str
    sun_elevation_deg: float | None = None
    sun_azimuth_deg: float | None = None
    lit_windows: float | None = None

    def to_dict(self) -> dict:
        return asdict(self)


def draw_lighting(spec, frame_index: int, time_of_day: str) -> Lighting:
    """Sun position (day) or lit-window fraction (night) of a frame."""
    if time_of_day not in TIMES:
        raise ValueError(f"unknown time of day {time_of_day!r}; known: day, night")
    g = stream(spec.seed, "frame", frame_index, "lighting", time_of_day)
    w = spec.weather
    if time_of_day == "day":
        return Lighting("day", float(g.uniform(*w.sun_elevation_deg)), float(g.uniform(*w.sun_azimuth_deg)))
    return Lighting("night", lit_windows=float(g.uniform(*w.lit_windows)))
