"""Spinning LiDAR sensors as data: beam tables, validated loading and the local ray fan.

A sensor is a YAML file (schema ``generator/spec/schemas/sensor.schema.json``): the shipped
presets live in ``generator/lidar/sensors/<name>.yaml`` (``hdl64e``, ``hdl32e``, ``vlp16``);
a user sensor is any file of the same form named by ``spec.sensors.lidar.sensor_file``.

Frames and conventions
----------------------
* Sensor frame like the ego frame: x forward, y left, z up, metres. Azimuths are
  counter-clockwise from +x seen from above, radians.
* Ring ``0`` is the HIGHEST beam, ring ``L-1`` the lowest (the row order of the
  SemanticKITTI-api range projection); ``laser_id`` keeps the device's own order.
* Column ``c`` of a sweep (``0 <= c < azimuth_steps``) fires at ``c / (steps * rotation_hz)``
  seconds after the sweep starts, with encoder azimuth
  ``psi_c = start_azimuth -/+ 2 pi c / steps`` (minus for a clockwise head).

Per-laser corrections, applied like the Velodyne ROS driver (``velodyne_pointcloud``,
``RawData::unpack``) converts a raw range ``d`` to a point, with ``v = vert_correction``,
``phi = psi + rot_correction``, ``vo = vert_offset_correction``, ``h = horiz_offset_correction``::

    x = (d cos v - vo sin v) cos phi - h sin phi
    y = (d cos v - vo sin v) sin phi + h cos phi
    z =  d sin v + vo cos v

i.e. a ray with unit direction ``(cos v cos phi, cos v sin phi, sin v)`` leaving the point
``vo (-sin v cos phi, -sin v sin phi, cos v) + h (-sin phi, cos phi, 0)``; ``d`` is the
distance along it. ``dist_correction`` (and the two-point ``_x``/``_y`` variants) calibrate
the range BIAS of a real unit, which its driver adds to the raw reading; a simulated
sensor measures true distances, so there is nothing to correct and they are ignored.
Focal distance/slope and min_intensity concern intensity calibration; ignored as well.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generator.errors import SpecError
from generator.lidar.returns import ReturnParams
from generator.spec.validate import check_ranges, load_schema, read_document, validate, with_defaults

#: Folder of the shipped sensor tables.
PRESET_DIR = Path(__file__).resolve().parent / "sensors"


@dataclass(frozen=True, eq=False)
class Sensor:
    """A spinning multi-beam LiDAR.

    Attributes
    ----------
    name, model, source : str
        Table name, device name, and the file it was read from.
    rotation_hz : float
        Spin rate; one sweep lasts :attr:`period_s`.
    azimuth_steps : int
        Firing columns per turn.
    min_range_m, max_range_m : float
        Hits nearer than ``min_range_m`` are blocked (no return); farther than ``max_range_m`` are misses.
    start_azimuth_rad : float
        Encoder azimuth of column 0 (pi = straight back).
    clockwise : bool
        Spin direction seen from above.
    laser_id : (L,) int16
        Device laser numbers in table order.
    ring : (L,) int16
        Elevation rank per laser, 0 = highest.
    elevation : (L,) float64
        ``vert_correction`` per laser, radians.
    rot_correction : (L,) float64
        Azimuth offset per laser, radians.
    vert_offset, horiz_offset : (L,) float64
        Emission point offsets per laser, metres.
    dist_correction : (L,) float64
        The real unit's range bias, metres; kept for reference, never applied.
    returns : ReturnParams
        How beams become points (:mod:`generator.lidar.returns`; ``model == "ideal"``: first hits).
    """

    name: str
    model: str
    source: str
    rotation_hz: float
    azimuth_steps: int
    min_range_m: float
    max_range_m: float
    start_azimuth_rad: float
    clockwise: bool
    laser_id: np.ndarray
    ring: np.ndarray
    elevation: np.ndarray
    rot_correction: np.ndarray
    vert_offset: np.ndarray
    horiz_offset: np.ndarray
    dist_correction: np.ndarray
    returns: ReturnParams = ReturnParams()

    @property
    def n_lasers(self) -> int:
        return len(self.laser_id)

    @property
    def period_s(self) -> float:
        """Duration of one sweep in seconds."""
        return 1.0 / self.rotation_hz

    @property
    def rays_per_sweep(self) -> int:
        return self.n_lasers * self.azimuth_steps

    @property
    def by_ring(self) -> np.ndarray:
        """(L,) int: table index of the laser on each ring (``by_ring[0]`` is the highest beam)."""
        return np.argsort(self.ring, kind="stable")

    def column_time(self) -> np.ndarray:
        """(steps,) float64: firing time of each column after the sweep start, seconds."""
        return np.arange(self.azimuth_steps, dtype=np.float64) / (self.azimuth_steps * self.rotation_hz)

    def column_azimuth(self) -> np.ndarray:
        """(steps,) float64: encoder azimuth of each column, radians, CCW from +x."""
        sign = -1.0 if self.clockwise else 1.0
        return self.start_azimuth_rad + sign * 2.0 * np.pi * np.arange(self.azimuth_steps) / self.azimuth_steps

    def local_rays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The full sweep's rays in the sensor frame, lasers ordered by ring.

        Returns
        -------
        origins : (steps, L, 3) float64
            Emission points (the driver's vertical/horizontal offsets), sensor frame, metres.
        directions : (steps, L, 3) float64
            Unit beam directions, sensor frame.
        azimuth : (steps, L) float64
            Beam azimuth ``psi_c + rot_correction``, radians, wrapped to [-pi, pi).
        """
        order = self.by_ring
        v = self.elevation[order][None, :]
        phi = self.column_azimuth()[:, None] + self.rot_correction[order][None, :]
        vo, h = self.vert_offset[order][None, :], self.horiz_offset[order][None, :]
        cv, sv, cp, sp = np.cos(v), np.sin(v), np.cos(phi), np.sin(phi)
        directions = np.stack([cv * cp, cv * sp, np.broadcast_to(sv, phi.shape)], -1)
        origins = np.stack([-vo * sv * cp - h * sp, -vo * sv * sp + h * cp, np.broadcast_to(vo * cv, phi.shape)], -1)
        azimuth = np.mod(phi + np.pi, 2.0 * np.pi) - np.pi
        return origins, directions, azimuth


def preset_names() -> list[str]:
    """Names of the shipped sensor tables."""
    return sorted(p.stem for p in PRESET_DIR.glob("*.yaml"))


def _rings(elevation: np.ndarray, laser_id: np.ndarray) -> np.ndarray:
    order = np.lexsort((laser_id, -elevation))
    ring = np.empty(len(order), np.int16)
    ring[order] = np.arange(len(order))
    return ring


def _laser_columns(doc: dict, source: str) -> dict[str, np.ndarray]:
    if "lasers" not in doc:
        u = doc["uniform"]
        lo, hi = (math.radians(a) for a in u["elevation_deg"])
        n = int(u["beams"])
        elev = np.linspace(hi, lo, n) if n > 1 else np.array([hi])
        zeros = np.zeros(n)
        return {"laser_id": np.arange(n, dtype=np.int16), "elevation": elev, "rot_correction": zeros,
                "vert_offset": zeros, "horiz_offset": zeros, "dist_correction": zeros, "ring": None}
    rows = doc["lasers"]
    ids = np.array([r["laser_id"] for r in rows], np.int16)
    if len(set(ids.tolist())) != len(ids):
        dup = next(i for i in ids.tolist() if ids.tolist().count(i) > 1)
        raise SpecError(source, "lasers", f"laser_id {dup} appears more than once")
    given = [r.get("ring") for r in rows]
    col = {"laser_id": ids,
           "elevation": np.array([r["vert_correction"] for r in rows], np.float64),
           "rot_correction": np.array([r["rot_correction"] for r in rows], np.float64),
           "vert_offset": np.array([r["vert_offset_correction"] for r in rows], np.float64),
           "horiz_offset": np.array([r["horiz_offset_correction"] for r in rows], np.float64),
           "dist_correction": np.array([r["dist_correction"] for r in rows], np.float64),
           "ring": None}
    if any(g is not None for g in given):
        if any(g is None for g in given):
            i = given.index(None)
            raise SpecError(source, f"lasers[{i}].ring", "is required when any laser gives a ring (or omit all rings)")
        expect = _rings(col["elevation"], ids)
        for i, (g, e) in enumerate(zip(given, expect, strict=False)):
            if g != e:
                raise SpecError(source, f"lasers[{i}].ring",
                                f"must be the elevation rank (0 = highest beam), expected {int(e)}, got {g}")
        col["ring"] = expect
    return col


def parse_sensor(doc: object, source: str) -> Sensor:
    """Validate a parsed sensor document and build the :class:`Sensor`.

    Raises
    ------
    SpecError
        ``<file>: <field>: <reason>`` for any schema or cross-field problem.
    """
    schema = load_schema("sensor")
    if not isinstance(doc, dict):
        raise SpecError(source, "(top level)", f"must be a mapping, got {type(doc).__name__}")
    validate(doc, schema, source)
    n_forms = ("lasers" in doc) + ("uniform" in doc)
    if n_forms != 1:
        raise SpecError(source, "lasers", "give exactly one of 'lasers' (per-laser table) or 'uniform' (even fan)"
                        + (", not both" if n_forms == 2 else ""))
    full = with_defaults(doc, schema)
    returns = ReturnParams(**full.pop("returns", {}))
    if "lasers" in doc:
        full.pop("uniform", None)  # with_defaults fills every absent object key with {}
        laser_schema = schema["$defs"]["laser"]
        full["lasers"] = [with_defaults(r, laser_schema, schema) for r in full["lasers"]]
    check_ranges(full, source)
    lo, hi = full["range_m"]
    if lo >= hi:
        raise SpecError(source, "range_m", f"min must be below max, got {full['range_m']}")
    col = _laser_columns(full, source)
    ring = col.pop("ring")
    if ring is None:
        ring = _rings(col["elevation"], col["laser_id"])
    return Sensor(
        name=full["name"], model=full.get("model", full["name"]), source=source,
        rotation_hz=float(full["rotation_hz"]), azimuth_steps=int(full["azimuth_steps"]),
        min_range_m=float(lo), max_range_m=float(hi),
        start_azimuth_rad=math.radians(full["start_azimuth_deg"]), clockwise=full["rotation"] == "clockwise",
        ring=ring, returns=returns, **col,
    )


def load_sensor(path: str | Path, source: str | None = None) -> Sensor:
    """Load and validate a sensor YAML file (see the module docstring for its meaning)."""
    source = str(path) if source is None else source
    return parse_sensor(read_document(path, source), source)


@functools.cache
def load_preset(name: str) -> Sensor:
    """A shipped sensor table by name (``hdl64e``, ``hdl32e``, ``vlp16``).

    Raises
    ------
    SpecError
        If there is no such preset.
    """
    path = PRESET_DIR / f"{name}.yaml"
    if not path.is_file():
        raise SpecError(
            "sensors.lidar.preset", "", f"unknown LiDAR preset {name!r}; known: {', '.join(preset_names())}"
        )
    return load_sensor(path, f"generator/lidar/sensors/{name}.yaml")


def sensor_for_spec(spec) -> Sensor:
    """The sensor a scene spec asks for: ``sensors.lidar.sensor_file`` (relative to the spec file) or the preset.

    Parameters
    ----------
    spec : generator.spec.SceneSpec

    Raises
    ------
    SpecError
        ``sensor_file`` absolute or leading out of the spec's folder (``..``, a link), or
        a bad sensor file; an unknown preset.
    """
    lidar = spec.sensors.lidar
    if lidar.sensor_file:
        from generator.safeload import confined_path

        # A path inside a spec stays inside the spec's folder: no absolute path, no '..', no link out.
        base = Path(spec.source).parent if spec.source else Path(".")
        path = confined_path(base, lidar.sensor_file, spec.source or "spec", "sensors.lidar.sensor_file")
        sensor = load_sensor(path, str(base / lidar.sensor_file))
    else:
        try:
            sensor = load_preset(lidar.preset)
        except SpecError as e:
            raise SpecError(spec.source or "spec", "sensors.lidar.preset", e.reason) from None
    return with_returns(sensor, getattr(lidar, "returns", None))


def with_returns(sensor: Sensor, returns: str | None) -> Sensor:
    """``sensor`` with the return model a spec or command line names.

    Parameters
    ----------
    returns : {None, "ideal", "strongest", "dual"}
        None keeps the sensor table's model; ``ideal`` switches the physical model off; ``strongest``
        and ``dual`` switch it on (the table's parameters, else the defaults) in that mode.
    """
    if returns is None:
        return sensor
    if returns == "ideal":
        params = dataclasses.replace(sensor.returns, model="ideal")
    else:
        params = dataclasses.replace(sensor.returns, model="physical", mode=returns)
    return dataclasses.replace(sensor, returns=params)
