"""Weather and time of day: the 6 x 2 combinations of seed 003 Table II and their draws.

Every parameter comes from a named stream of the spec's seed, so the camera image of a
frame and the LiDAR scan of the same frame see the same weather:

* ``wetness`` and ``puddle_seed``: per frame (``("frame", k, "wet")``) -- the wet render of a
  frame is shared by its wet, wet_fog, rain and rain_fog variants;
* fog visibility and rain rate: per frame and kind (``("frame", k, "weather", kind)``);
* sun position and lit-window fraction: per frame and time of day
  (``("frame", k, "lighting", time)``);
* cloud cover and the cloud pattern: per frame and time of day (``("frame", k, "clouds", time)``,
  a stream of its own so the sun positions drawn before clouds existed stay the same).

Times of day: ``day`` (sun from low morning light to noon), ``dusk`` (sun a few degrees above
or below the horizon, street lamps, windows and vehicle lights on) and ``night``. A plan holds
``day`` and ``night`` (seed 003's Table II) unless the spec's ``weather.times_of_day`` lists
others (:func:`combinations`).

Sky: every variant but ``clear`` is overcast (:func:`is_overcast`): when it rains, when it is
foggy, and when the ground is wet after rain the sky is one grey cloud deck and the sun a dim,
diffuse light. ``clear`` skies carry broken clouds of the drawn cover. A frame's six weather
variants cost three renders per time of day: the dry, sunny render gives ``clear``; the dry,
overcast one ``fog``; the wet, overcast one ``wet``, ``wet_fog``, ``rain`` and ``rain_fog``
(:func:`render_key`). Fog and rain are applied in post-processing from the depth pass.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from generator.rng import stream

KINDS = ("clear", "fog", "rain", "rain_fog", "wet", "wet_fog")
#: Every time of day urbangen renders, in table order.
TIMES = ("day", "dusk", "night")
#: The times of day of a plan unless the spec lists others (seed 003's day and night).
DEFAULT_TIMES = ("day", "night")
#: Times of day whose street lamps, lit windows and vehicle lights are on.
LIT_TIMES = ("dusk", "night")
#: Koschmieder: visibility V (m) = 3.912 / beta (contrast threshold 2 %).
KOSCHMIEDER = 3.912

# -- daylight and street light, in the renders' units (shared by the Blender lights and the post fx) --
#: Irradiance of the sun (render units, on a surface facing it) at :data:`REFERENCE_ELEVATION_DEG`: a
#: sunlit grey surface lands near 0.5 (linear); it stands for ~100 klx.
SUN_STRENGTH = 3.2
#: The clear day the camera's EV 0 is metered on has the sun at this elevation.
REFERENCE_ELEVATION_DEG = 41.0
#: Render units (W/m^2 of irradiance, or W/(m^2 sr) of radiance) per lux (or per cd/m^2).
UNITS_PER_LUX = SUN_STRENGTH / 100_000.0
#: Clear-sky global horizontal illuminance (lux) against sun elevation (deg): the standard curves
#: (civil twilight ends at -6 deg near 3 lux, sunset ~600 lux, a 60 deg sun ~85 klx).
GLOBAL_LUX = ((-8.0, 0.5), (-6.0, 3.4), (-4.0, 20.0), (-2.0, 110.0), (0.0, 600.0), (2.0, 1500.0), (5.0, 4000.0),
              (10.0, 10_000.0), (20.0, 25_000.0), (30.0, 42_000.0), (45.0, 65_000.0), (60.0, 85_000.0),
              (90.0, 110_000.0))
#: Overcast: the deck's horizontal illuminance as a share of the clear sky's, and the share of the
#: sun's direct light left (a dim, diffuse sun).
OVERCAST_SHARE = 0.22
OVERCAST_SUN = 0.08
#: Horizontal illuminance on the road under a street lamp (lux): what lights a street at dusk and night.
STREET_LUX = 60.0


def global_irradiance(elevation_deg: float) -> float:
    """Clear-sky global horizontal irradiance (render units) at a sun elevation (log-interpolated
    :data:`GLOBAL_LUX`)."""
    el, lux = np.array(GLOBAL_LUX).T
    return float(np.exp(np.interp(elevation_deg, el, np.log(lux)))) * UNITS_PER_LUX


def light_level(light: Lighting) -> float:
    """How much light the scene of ``light`` has, relative to the reference clear day (1.0).

    Day and dusk: the global horizontal irradiance of the sky (x :data:`OVERCAST_SHARE` +
    :data:`OVERCAST_SUN` when overcast); dusk and night: at least the street lamps' light on the
    road. The post fx (fog airlight, emitter thresholds, rain streaks), written for a clear day's
    radiance, work on the render divided by this level.
    """
    level = 0.0
    if light.sun_elevation_deg is not None:
        level = global_irradiance(light.sun_elevation_deg) / global_irradiance(REFERENCE_ELEVATION_DEG)
        if light.overcast:
            level *= OVERCAST_SHARE + OVERCAST_SUN
    if light.time_of_day in LIT_TIMES:
        level = max(level, STREET_LUX * UNITS_PER_LUX / global_irradiance(REFERENCE_ELEVATION_DEG))
    return level


def combinations(times=DEFAULT_TIMES) -> list[tuple[str, str]]:
    """The (time_of_day, weather_kind) combinations of ``times``, in Table II order (weather-major).

    The default gives the 12 of seed 003 (day and night); ``combinations(TIMES)`` every one
    urbangen knows (what names in a plan, a manifest or metadata are checked against).
    """
    unknown = [t for t in times if t not in TIMES]
    if unknown:
        raise ValueError(f"unknown time of day {unknown[0]!r}; known: {', '.join(TIMES)}")
    times = [t for t in TIMES if t in times]
    return [(t, k) for k in KINDS for t in times]


def lidar_combination(frame_index: int, times=DEFAULT_TIMES) -> tuple[str, str]:
    """The combination whose weather the LiDAR scan of a frame shares (balanced round-robin)."""
    combos = combinations(times)
    return combos[frame_index % len(combos)]


def is_overcast(kind: str) -> bool:
    """True for the kinds under an overcast sky: rain, fog, and wet ground after rain (all but clear)."""
    return kind != "clear"


def render_key(kind: str) -> tuple[bool, bool]:
    """(wet, overcast): the render a weather kind is made from (fog and rain are added in post)."""
    return is_wet(kind), is_overcast(kind)


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
    """Time of day and its drawn parameters.

    Attributes
    ----------
    time_of_day : str
        One of :data:`TIMES`.
    sun_elevation_deg, sun_azimuth_deg : float or None
        Sun position (day and dusk; at dusk the elevation may be below 0: twilight). Degrees,
        azimuth a compass bearing (0 = north = +y, 90 = east = +x).
    lit_windows : float or None
        Fraction of windows lit (dusk and night).
    cloud_cover : float
        0 (clear sky) .. 1 (overcast): the share of the sky the clouds cover.
    cloud_seed : float
        Moves the procedural cloud pattern (a new draw per frame and time of day).
    overcast : bool
        One closed cloud deck: a grey sky and a dim, diffuse sun (see :func:`is_overcast`).
    """

    time_of_day: str
    sun_elevation_deg: float | None = None
    sun_azimuth_deg: float | None = None
    lit_windows: float | None = None
    cloud_cover: float = 0.0
    cloud_seed: float = 0.0
    overcast: bool = False

    def to_dict(self) -> dict:
        return asdict(self)


def draw_lighting(spec, frame_index: int, time_of_day: str, kind: str = "clear") -> Lighting:
    """Sun position (day, dusk), lit-window fraction (dusk, night) and clouds of a frame's variant.

    The sun and the windows come from ``("frame", k, "lighting", time_of_day)`` (day: elevation,
    azimuth; night: windows, as before clouds existed; dusk: elevation, azimuth, windows), the
    clouds from ``("frame", k, "clouds", time_of_day)``: every variant of a frame and time of day
    sees the same sun and cloud pattern, the overcast ones (:func:`is_overcast`) with a closed deck.
    """
    if time_of_day not in TIMES:
        raise ValueError(f"unknown time of day {time_of_day!r}; known: {', '.join(TIMES)}")
    if kind not in KINDS:
        raise ValueError(f"unknown weather kind {kind!r}; known: {', '.join(KINDS)}")
    g = stream(spec.seed, "frame", frame_index, "lighting", time_of_day)
    w = spec.weather
    gc = stream(spec.seed, "frame", frame_index, "clouds", time_of_day)
    cover, cloud_seed = float(gc.uniform(*w.cloud_cover)), float(gc.uniform(0.0, 1000.0))
    overcast = is_overcast(kind)
    clouds = {"cloud_cover": 1.0 if overcast else cover, "cloud_seed": cloud_seed, "overcast": overcast}
    if time_of_day == "day":
        return Lighting("day", float(g.uniform(*w.sun_elevation_deg)), float(g.uniform(*w.sun_azimuth_deg)), **clouds)
    if time_of_day == "dusk":
        el, az = float(g.uniform(*w.dusk_sun_elevation_deg)), float(g.uniform(*w.sun_azimuth_deg))
        return Lighting("dusk", el, az, lit_windows=float(g.uniform(*w.lit_windows)), **clouds)
    if not overcast:  # a clear night sky is drawn without clouds (they would be unlit against the glow)
        clouds["cloud_cover"] = 0.0
    return Lighting("night", lit_windows=float(g.uniform(*w.lit_windows)), **clouds)
