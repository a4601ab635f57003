"""The per-scan post-processing chain: intensity model -> domain gap -> LiDAR weather.

Each stage draws from its own named stream of the spec's seed, so switching one stage
on or off never changes the draws of another:

=============== ==============================================
stage           stream
=============== ==============================================
intensity       ``("frame", k, "lidar_intensity")``
laser gains     ``("lidar_sensor", "intensity_gain")`` (once)
domain gap      ``("frame", k, "lidar_domain_gap")``
weather         ``("frame", k, "lidar_weather")``
=============== ==============================================

The laser gains are the physical sensor's intensity calibration spread (:mod:`generator.lidar.returns`):
each laser's remission times its own gain (log-normal, mean 1), clipped to [0, 1]; off with the ideal sensor.

The weather comes last because it is physics the scan should show whatever the
processing before it: it multiplies every remission by the two-way transmission, including
the domain gap's constant intensity (so a foggy scan under the seed002 preset is no longer
constant), and drops points by received power, which depends on the surface, not on the
remission written.

:func:`process_scan` returns the processed points plus a record of what each stage did
(``lidar_meta.json`` keeps one per scan); :meth:`ScanProcessing.describe` gives the
parameters once per sequence.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from generator.remission.models import IntensityFn, intensity_fn_for_spec
from generator.rng import stream
from generator.scan_effects.domain_gap import DomainGap, apply_to_points, gap_for_spec
from generator.scan_effects.weather import (
    LidarWeatherParams,
    apply_lidar_weather,
    enabled_for_spec,
    frame_weather,
    weather_config,
)

ORDER = "intensity model -> domain gap -> LiDAR weather"
ORDER_GAINS = "intensity model -> laser gains (physical sensor) -> domain gap -> LiDAR weather"


@dataclass(frozen=True)
class ScanProcessing:
    """What happens to every scan after the cast.

    Attributes
    ----------
    intensity_fn : IntensityFn
    domain_gap : DomainGap or None
        None = off.
    weather : LidarWeatherParams or None
        None = off (clear, loss-free scans).
    laser_gain : (256,) float32 or None
        Remission gain per device laser id (the physical sensor's intensity calibration spread); None = off.
    """

    intensity_fn: IntensityFn
    domain_gap: DomainGap | None = None
    weather: LidarWeatherParams | None = None
    laser_gain: np.ndarray | None = None
    laser_ids: tuple = ()

    def describe(self) -> dict:
        """The parameters, for ``lidar_meta.json``."""
        return {
            "order": ORDER if self.laser_gain is None else ORDER_GAINS,
            "intensity": dict(getattr(self.intensity_fn, "description",
                                      {"model": getattr(self.intensity_fn, "__name__", "custom")})),
            **({} if self.laser_gain is None else {"laser_gain": {
                "by_laser_id": {str(i): round(float(self.laser_gain[i]), 5) for i in self.laser_ids},
                "draw": "log-normal, mean 1, sigma = intensity_gain_spread; "
                        "stream ('lidar_sensor', 'intensity_gain')"}}),
            "domain_gap": None if self.domain_gap is None else {"source": "seed 002 sec. 3.2 / 4.1.2",
                                                                **self.domain_gap.to_dict()},
            "weather": None if self.weather is None else {
                "detection_threshold": self.weather.detection_threshold, "min_range_m": self.weather.min_range_m,
                "frame_weather": "generator.weather.draw_weather(spec, k, lidar_combination(k)[1])",
                "constants": weather_config()},
        }


def processing_for_spec(spec, sensor=None, weather_default: bool = False,
                        intensity_fn: IntensityFn | None = None) -> ScanProcessing:
    """The chain the spec asks for.

    Parameters
    ----------
    spec : generator.spec.SceneSpec
    sensor : generator.lidar.sensors.Sensor, optional
        Its minimum range starts the fog soft returns (default 0.9 m).
    weather_default : bool
        LiDAR weather when ``spec.lidar.weather.enabled`` is null (auto): True for datasets
        whose images carry weather (``generate``), False for the plain ``lidar`` command.
    intensity_fn : IntensityFn, optional
        Overrides the spec's intensity model.
    """
    weather = None
    physical = sensor is not None and sensor.returns.physical
    if enabled_for_spec(spec, weather_default):
        if physical:  # the scanner detects; the weather adds the wet-ground loss at the sensor's threshold
            weather = LidarWeatherParams(sensor.returns.detection_threshold, float(sensor.min_range_m), received=True)
        else:
            weather = LidarWeatherParams(spec.lidar.weather.detection_threshold,
                                         0.9 if sensor is None else float(sensor.min_range_m))
    return ScanProcessing(intensity_fn_for_spec(spec) if intensity_fn is None else intensity_fn,
                          gap_for_spec(spec), weather, laser_gains(sensor, spec.seed) if physical else None,
                          tuple(int(i) for i in sensor.laser_id) if physical else ())


def laser_gains(sensor, seed: int) -> np.ndarray:
    """(256,) float32 remission gain per device laser id: log-normal, mean 1, sigma ``intensity_gain_spread``
    (1 for ids the sensor does not have), drawn from ``stream(seed, "lidar_sensor", "intensity_gain")``."""
    s = float(sensor.returns.intensity_gain_spread)
    draw = stream(seed, "lidar_sensor", "intensity_gain").standard_normal(len(sensor.laser_id))
    out = np.ones(256, np.float32)
    out[np.asarray(sensor.laser_id, np.int64)] = np.exp(s * draw - s * s / 2)
    return out


def process_scan(points: np.ndarray, processing: ScanProcessing, spec, frame_index: int,
                 part: str | None = None) -> tuple[np.ndarray, np.ndarray, dict]:
    """Run the chain on the points of frame ``frame_index``.

    ``part`` names a second set of points of the same frame (``"second_return"``: the second returns
    of a dual scan), processed on streams of their own (the frame's names plus ``part``), so the
    strongest returns of a dual scan come out as the points of a strongest scan, byte for byte.

    Parameters
    ----------
    points : (n,) POINT_DTYPE
        As cast (:mod:`generator.lidar.scan`).

    Returns
    -------
    points : (m,) POINT_DTYPE
        The points that remain (x, y, z, range possibly moved; soft returns relabelled 0).
    remission : (m,) float32 in [0, 1]
    record : dict
        ``frame``, ``points_cast``, ``points``, and per stage what it did (None = off).
    """
    seed = spec.seed
    more = () if part is None else (part,)
    record = {"frame": int(frame_index), "points_cast": int(len(points)), "domain_gap": None, "weather": None}
    remission = np.asarray(
        processing.intensity_fn(points, stream(seed, "frame", frame_index, "lidar_intensity", *more)), np.float32
    )
    if processing.laser_gain is not None:
        remission = np.clip(remission * processing.laser_gain[points["laser"]], 0.0, 1.0).astype(np.float32)
    if processing.domain_gap is not None:
        points, remission, record["domain_gap"] = apply_to_points(
            points, remission, processing.domain_gap, stream(seed, "frame", frame_index, "lidar_domain_gap", *more))
    if processing.weather is not None:
        tod, w = frame_weather(spec, frame_index)
        points, remission, info = apply_lidar_weather(points, remission, w, processing.weather,
                                                      stream(seed, "frame", frame_index, "lidar_weather", *more))
        record["weather"] = {"time_of_day": tod, **info}
    record["points"] = int(len(points))
    return points, remission, record
