"""Typed scene spec: frozen dataclasses mirroring ``schemas/scene.schema.json``.

Defaults live in the schema only; :func:`generator.spec.load.load_spec` fills them in
before these classes are built, so every field here is always present.
Lengths in metres, angles in degrees (as written in the spec).
"""

from __future__ import annotations

import dataclasses
import types
import typing
from dataclasses import dataclass

Range = tuple[float, float]
Vec3 = tuple[float, float, float]


@dataclass(frozen=True)
class Town:
    blocks_x: int
    blocks_y: int
    block_size_m: float
    block_size_jitter_m: float
    lanes_per_direction: int
    lane_width_m: float
    parking_strip_width_m: float
    sidewalk_width_m: float
    curb_height_m: float
    margin_m: float
    #: image frames per town of a ``generate`` run; None = one town (see :mod:`generator.spec.towns`)
    redraw_every_frames: int | None = None

    @property
    def road_width_m(self) -> float:
        """Kerb-to-kerb width of a street: lanes both ways plus both parking strips."""
        return 2 * self.lanes_per_direction * self.lane_width_m + 2 * self.parking_strip_width_m


@dataclass(frozen=True)
class Density:
    buildings: float
    trees_per_100m: float
    bushes_per_100m: float
    hedges: float
    fences: float
    parked_cars_per_100m: float
    truck_fraction: float
    moving_cars_per_100m: float
    people_per_100m: float
    signs_per_block: float
    lamp_spacing_m: float
    parks: float
    street_objects_per_100m: float
    bike_racks_per_block: float
    parked_two_wheelers_per_100m: float
    riders_per_km: float
    bus_stops_per_km: float
    trams: int
    other_vehicles_per_100m: float
    walls: float
    driveways: float
    gravel: float


@dataclass(frozen=True)
class Heights:
    building_m: Range
    floor_m: float
    tree_m: Range
    person_m: Range


@dataclass(frozen=True)
class Paths:
    spacing_m: float
    yaw_jitter_deg: float
    pitch_jitter_deg: float
    roll_jitter_deg: float
    speed_mps: float
    clearance_m: float


@dataclass(frozen=True)
class Counts:
    """Exact actors per scene (``traffic.counts``); None = the kind's density decides."""

    cars: int | None = None
    trucks: int | None = None
    vans: int | None = None
    buses: int | None = None
    other_vehicles: int | None = None
    cyclists: int | None = None
    motorcyclists: int | None = None
    pedestrians: int | None = None
    standing_pedestrians: int | None = None


@dataclass(frozen=True)
class Traffic:
    cars_per_km: float
    trucks_per_km: float
    buses_per_km: float
    other_vehicles_per_km: float
    cyclists_per_km: float
    motorcyclists_per_km: float
    pedestrians_per_100m: float
    standing_pedestrians_per_100m: float
    speed_limit_mps: float
    pedestrian_speed_mps: float
    ego_stop_probability: float
    vans_per_km: float = 0.0
    counts: Counts | None = None

    @property
    def enabled(self) -> bool:
        """Whether anything moves besides the ego (all densities and counts 0: the frozen town)."""
        counts = dataclasses.asdict(self.counts).values() if self.counts is not None else ()
        return any(v > 0 for k, v in dataclasses.asdict(self).items() if k.endswith(("_per_km", "_per_100m"))) \
            or any(v is not None and v > 0 for v in counts)


@dataclass(frozen=True)
class Camera:
    hfov_deg: float
    xyz_m: Vec3
    rpy_deg: Vec3


@dataclass(frozen=True)
class Lidar:
    preset: str
    sensor_file: str | None
    xyz_m: Vec3
    rpy_deg: Vec3
    motion_skew: bool
    #: None = the sensor table's model; "ideal", "strongest" or "dual" (:mod:`generator.lidar.returns`)
    returns: str | None = None


@dataclass(frozen=True)
class Stereo:
    enabled: bool
    baseline_m: float
    every: int


@dataclass(frozen=True)
class Sensors:
    camera: Camera
    lidar: Lidar
    stereo: Stereo


@dataclass(frozen=True)
class Weather:
    fog_visibility_m: Range
    rain_rate_mmh: Range
    wetness: Range
    sun_elevation_deg: Range
    sun_azimuth_deg: Range
    lit_windows: Range
    dusk_sun_elevation_deg: Range
    cloud_cover: Range
    times_of_day: tuple[str, ...]


@dataclass(frozen=True)
class DomainGap:
    enabled: bool
    dropout: float
    jitter_m: float
    constant_intensity: float | None


@dataclass(frozen=True)
class LidarWeather:
    enabled: bool | None
    detection_threshold: float


@dataclass(frozen=True)
class LidarProcessing:
    intensity_model: str
    intensity_profile: str | None
    constant_intensity: float
    domain_gap: DomainGap
    weather: LidarWeather


@dataclass(frozen=True)
class Labels:
    openlabel_min_points: int


@dataclass(frozen=True)
class Streets:
    """Street variety: weights of the cross-section types and districts, parking occupancy range.

    Weights are relative (``{"plain": 1, "boulevard": 3}``: a boulevard three times as often as a
    plain street); the draws are made in :mod:`generator.layout.network.draw` and
    :mod:`generator.layout.lots.districts`.
    """

    types: dict
    parking_occupancy: Range
    verge_trees_per_100m: float
    verge_bushes_per_100m: float
    verge_hedges: float
    districts: dict
    #: share of the four-arm intersections that are roundabouts (:mod:`generator.layout.network.roundabouts`)
    roundabouts: float = 0.0
    #: share of the eligible interior segments closed and made pocket parks (:mod:`generator.layout.network.closures`)
    closed_streets: float = 0.0
    #: [low, high] degrees the two street directions cross at, one draw per town
    #: (:mod:`generator.layout.mapping.town_map`)
    intersection_angle_deg: Range = (90.0, 90.0)
    #: "either": each side of a residential street parking or verge at even odds; "parking_and_verge":
    #: one side each (:mod:`generator.layout.network.cross_sections`)
    residential_strips: str = "either"
    #: types route 0's streets take in turn, in driving order (None: drawn like every street)
    drive_types: tuple | None = None


@dataclass(frozen=True)
class Variants:
    """Distinct prototype meshes per kind in one asset library (``assets.variants``)."""

    car: int = 48
    person: int = 48
    truck: int = 8
    bus: int = 6
    bicyclist: int = 8
    motorcyclist: int = 8
    construction_vehicle: int = 4
    box_van: int = 4


@dataclass(frozen=True)
class Assets:
    """Asset variety (``assets``): variants per kind, how often re-drawn towns draw a fresh library,
    the share of children among the people."""

    variants: Variants = Variants()
    redraw_every_towns: int | None = 1
    child_share: float = 0.14


@dataclass(frozen=True)
class SceneSpec:
    """A validated scene spec (see ``schemas/scene.schema.json`` for every field's meaning).

    Attributes
    ----------
    source : str
        The file it was read from (for messages; relative paths in the spec resolve against it).
    spec_hash : str
        SHA-256 of the canonical JSON of the spec with defaults filled in (``town.redraw_every_frames``
        left out while it is null, so specs written before the option keep their hash).
    town_index : int or None
        Set on the spec of town ``i`` of a re-drawn run (:func:`generator.spec.towns.town_spec`),
        whose ``seed`` is then the town's seed; None for the spec as read.
    asset_seed : int or None
        The seed of the asset library (prototype meshes) when it differs from ``seed``: the
        towns of one run share the library of the spec's own seed. None = ``seed``.
    """

    name: str
    seed: int
    town: Town
    density: Density
    heights: Heights
    paths: Paths
    traffic: Traffic
    sensors: Sensors
    weather: Weather
    lidar: LidarProcessing
    labels: Labels
    streets: Streets | None = None
    assets: Assets = Assets()
    source: str = ""
    spec_hash: str = ""
    town_index: int | None = None
    asset_seed: int | None = None

    def to_dict(self) -> dict:
        """The spec as plain JSON-able data (without ``source``, ``spec_hash``, ``town_index``, ``asset_seed``)."""
        d = dataclasses.asdict(self)
        for key in ("source", "spec_hash", "town_index", "asset_seed"):
            d.pop(key)
        if d["streets"] is None:      # absent: the spec (and its hash) reads as before the field existed
            d.pop("streets")
        return _lists(d)


def _lists(x):
    if isinstance(x, dict):
        return {k: _lists(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_lists(v) for v in x]
    return x


def build(cls, data: dict):
    """Construct dataclass ``cls`` from validated, default-filled ``data`` (recursively)."""
    hints = typing.get_type_hints(cls)
    kwargs = {}
    for f in dataclasses.fields(cls):
        if f.name not in data:
            continue
        t, v = hints[f.name], data[f.name]
        if typing.get_origin(t) in (typing.Union, types.UnionType) and isinstance(v, dict):
            t = next(a for a in typing.get_args(t) if dataclasses.is_dataclass(a))   # ``Streets | None`` given
        if dataclasses.is_dataclass(t):
            v = build(t, v)
        elif typing.get_origin(t) is tuple and typing.get_args(t)[0] is str:
            v = tuple(str(x) for x in v)
        elif typing.get_origin(t) is tuple:
            v = tuple(float(x) for x in v)
        elif t is float and isinstance(v, int):
            v = float(v)
        kwargs[f.name] = v
    return cls(**kwargs)
