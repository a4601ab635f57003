"""The per-scan post-processing chain: intensity model -> domain gap -> LiDAR weather.

Each stage draws from its own named stream of the spec's seed, so switching one stage
on or off never changes the draws of another:

=============== ==============================================
stage           stream
=============== ==============================================
intensity       ``("frame", k, "lidar_intensity")``
domain gap      ``("frame", k, "lidar_domain_gap")``
weather         ``("frame", k, "lidar_weather")``
=============== ==============================================

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

from generator.scan_effects.domain_gap import DomainGap, apply_to_points, gap_for_spec
from generator.remission.models import IntensityFn, intensity_fn_for_spec
from generator.scan_effects.weather import (LidarWeatherParams, apply_lidar_weather, enabled_for_spec, frame_weather,
                                     weather_config)
from generator.rng import stream

ORDER = "intensity model -> domain gap -> LiDAR weather"


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
    """

    intensity_fn: IntensityFn
    domain_gap: DomainGap | None = None
    weather: LidarWeatherParams | None = None

    def describe(self) -> dict:
        """The parameters, for ``lidar_meta.json``."""
        return {
            "order": ORDER,
            "intensity": dict(getattr(self.intensity_fn, "description",
                                      {"model": getattr(self.intensity_fn, "__name__", "custom")})),
            "domain_gap": None if self.domain_gap is None else {"source": "seed 002 sec. 3.2 / 4.1.2", **self.domain_gap.to_dict()},
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
    if enabled_for_spec(spec, weather_default):
        weather = LidarWeatherParams(spec.lidar.weather.detection_threshold,
                                     0.9 if sensor is None else float(sensor.min_range_m))
    return ScanProcessing(intensity_fn_for_spec(spec) if intensity_fn is None else intensity_fn,
                          gap_for_spec(spec), weather)


def process_scan(points: np.ndarray, processing: ScanProcessing, spec, frame_index: int) -> tuple[np.ndarray, np.ndarray, dict]:
    """Run the chain on the points of frame ``frame_index``.

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
    record = {"frame": int(frame_index), "points_cast": int(len(points)), "domain_gap": None, "weather": None}
    remission = np.asarray(processing.intensity_fn(points, stream(seed, "frame", frame_index, "lidar_intensity")), np.float32)
    if processing.domain_gap is not None:
        points, remission, record["domain_gap"] = apply_to_points(
            points, remission, processing.domain_gap, stream(seed, "frame", frame_index, "lidar_domain_gap"))
    if processing.weather is not None:
        tod, w = frame_weather(spec, frame_index)
        points, remission, info = apply_lidar_weather(points, remission, w, processing.weather,
                                                      stream(seed, "frame", frame_index, "lidar_weather"))
        record["weather"] = {"time_of_day": tod, **info}
    record["points"] = int(len(points))
    return points, remission, record
