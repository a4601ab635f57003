"""The physical sensor's part of writing a sequence: its return model, each sweep's extinction, second returns.

Dual scans (:mod:`generator.lidar.returns`) keep one point per beam, its strongest return, in
``velodyne/`` and ``labels/`` (and in every per-point side file): exactly the points of strongest mode.
The second returns are written beside them in the same formats, so any KITTI reader reads them:

=============================================  =======  =============================================
file                                           dtype    content
=============================================  =======  =============================================
``second_return/velodyne/NNNNNN.bin``          float32  x, y, z, remission per second return
``second_return/labels/NNNNNN.label``          uint32   SemanticKITTI raw id | instance << 16
``second_return/first_index/NNNNNN.bin``       uint32   row of the same beam's strongest return in
                                                        ``velodyne/NNNNNN.bin`` (0xFFFFFFFF if the
                                                        post-processing dropped that one)
=============================================  =======  =============================================

The second returns go through the same post-processing (intensity, domain gap, weather) on streams
of their own (``(..., "second_return")``), so the strongest returns' bytes do not depend on the mode.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from generator.atomic import write_bytes
from generator.formats import semantickitti as sk
from generator.labels.sets import semantickitti_labels
from generator.lidar.returns import ReturnModel, optics_from_materials
from generator.lidar.sensors import Sensor
from generator.remission.models import reflectivity_config
from generator.scan_effects.weather import extinction_per_m, frame_weather

SECOND_DIR = "second_return"


def return_model(sensor: Sensor, seed: int) -> ReturnModel | None:
    """The physical return model of ``sensor`` for a dataset of ``seed`` (None: the ideal sensor)."""
    if not sensor.returns.physical:
        return None
    p = reflectivity_config()["physical"]
    optics = optics_from_materials(p["retro_gain"], p["retro_exponent"], p["reference_range_m"], p["min_range_m"])
    return ReturnModel.build(sensor, optics, seed)


def sweep_alpha(spec, processing, frame_index: int) -> float:
    """Extinction (fog + rain, 1/m) the physical sensor sees in sweep ``frame_index`` (0 without LiDAR weather)."""
    if processing.weather is None:
        return 0.0
    return float(sum(extinction_per_m(frame_weather(spec, frame_index)[1])))


def write_second_returns(seq: Path, stem: str, first: np.ndarray, other: np.ndarray, remission: np.ndarray,
                         n_lasers: int) -> None:
    """Write the second returns ``other`` (with their ``remission``) of a dual scan whose strongest returns
    are ``first`` (see the module docstring)."""
    key_first = first["column"].astype(np.int64) * n_lasers + first["ring"]
    key_other = other["column"].astype(np.int64) * n_lasers + other["ring"]
    at = np.minimum(np.searchsorted(key_first, key_other), max(len(first) - 1, 0))
    found = (len(first) > 0) & (key_first[at] == key_other) if len(first) else np.zeros(len(other), bool)
    index = np.where(found, at, 0xFFFFFFFF).astype("<u4")
    sk.write_scan(seq / SECOND_DIR / "velodyne" / f"{stem}.bin", np.stack([other["x"], other["y"], other["z"]], -1),
                  remission)
    sk.write_labels(seq / SECOND_DIR / "labels" / f"{stem}.label",
                    semantickitti_labels(other["class"], other["moving"]),
                    other["instance"])
    write_bytes(seq / SECOND_DIR / "first_index" / f"{stem}.bin", index.tobytes())
