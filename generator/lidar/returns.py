"""A sensor that misses and blurs like a real one: received power, beam divergence, return modes, noise.

Off (``returns: {model: ideal}`` in a sensor table, or ``sensors.lidar.returns: "ideal"`` in a spec)
every ray's first hit is a point, as before, byte for byte. On (the ``hdl64e`` preset), each beam's
returns come from its received power (the *waveform* of :mod:`generator.lidar.return_kernels`):

Received power, normalised so that a Lambertian target of reflectivity 1 at ``R0`` = 10 m, seen at
normal incidence in clear air, gives 1 (the ``physical`` intensity model's scale)::

    P = w * tau * rho * (cos^k + lobe_gain * cos^lobe_exponent) * (R0 / max(R, R_min))^2 * exp(-2 alpha R)

``rho`` is the material's 905 nm reflectivity (``generator/materials.yaml``; 0.002 for glass, whose own
reflection is the mirror glint, Lambertian: ``k = 1``), the lobe is the
retroreflective lobe of lane paint and signs (``reflectivity.yaml``) or the specular glint of glass,
``k`` the incidence exponent (rough ground and walls scatter back far more at grazing incidence than
Lambert's cosine: with k = 1 the S3 datasheet's "50 m on 10 % pavement" could never hold for the
road ahead, seen at 2 degrees; k = 0.25 keeps asphalt to ~28 m and concrete to ~45 m ahead),
``alpha`` the atmosphere's extinction (fog and rain of the frame's weather), ``w`` the share of the
beam's power a sub-ray carries and ``tau`` what the glass it crossed let through. A return is
detected when its power reaches ``detection_threshold``.

Beam divergence: a beam is a Gaussian footprint of full angle ``divergence_mrad`` (1/e^2), sampled by
``subrays`` rays (the centre and ``subrays - 1`` evenly round a circle; equal shares of the power),
but only where the footprint can straddle an edge: where the central rays of the beam and its four
neighbours in the range image do not see one continuous surface (a hit next to a miss, another class
or instance, or a range step between neighbouring columns). Elsewhere the footprint lies on the
surface the centre hits and every sub-ray would return the centre's range. An object thinner than
the 3 mrad column spacing that no central ray touches stays invisible (as without divergence). The
same holds inside an edge beam (``edge_subrays: differing``, the default): only the sub-rays towards
the neighbours that differ are cast (the probes); a sub-ray towards a neighbour that sees the
centre's surface is taken to see it too, and its share of the power goes to the centre's hit. So is a
probe whose line lands inside the centre's own triangle (a town face) at a range within the split step,
where what the neighbour on its side sees cannot stand in front of that point (it lies behind the
triangle's plane, or on a plane the probe's line does not cross before it; a neighbour on the same plane,
such as parking next to road, does not count as behind): it is not cast (about a third of the probes in the
default town; :func:`generator.lidar.probe_skip.probes_on_centre`). ``edge_subrays: all`` casts every
sub-ray of a beam whose probes find an edge.

Glass (materials with a ``transmittance``): the pane returns its own weak diffuse reflectance and a
specular glint near normal incidence, and lets ``transmittance`` of the power through; the beam goes
on (up to ``glass_layers`` panes). Behind the glass of most objects lies an interior the scene does
not model: a continued beam that meets the same object (same class and instance) again is absorbed
there, and a free-standing pane (a shelter, a glass wall panel) shows what stands behind it. A car's
cabin is modelled (seats, dashboard, door cards, floor, headliner; the classes listed as
``interiors``): the beam goes on into it and returns from the opaque faces of its own vehicle it
meets there, as the camera sees them through the transparent glass; meeting its own vehicle's glass
again (the far window) or anything else (through a seam of the body), it is absorbed, so it never
leaves the vehicle. Two kinds of pane end the beam at once, without casting it on: a building's
facade glass (``behind: room`` in ``materials.yaml``: the room absorbs the beam, and the scene's
buildings have no floor, so a beam cast on would meet the ground under the building) and the windows
of vehicles whose cabin is not modelled (the classes listed as ``cabins``: trucks, buses, trams;
cast on, the beam could only meet its own vehicle again, or slip out through a seam of the body):
their windows are the holes of real scans.

Waveform: each beam's hits (sub-rays, panes, what lies behind them) sorted by range; hits closer
than ``separation_m`` (half the pulse length, ``c tau / 2``) merge into one return whose range is
their power-weighted mean (a *mixed* point when they come from different surfaces: different class
or instance, or normals more than 30 degrees apart), labelled with the surface that carries most of
its power. Return modes: ``strongest`` (KITTI's; one point per beam) or ``dual`` (the strongest and
the last, as the HDL-64E S3 reports them; when the strongest is also the last, the second strongest,
as Velodyne's dual mode does).

Range noise: each return's range gets ``N(0, sigma_l)``, ``sigma_l`` the laser's own standard
deviation (drawn once per sensor unit around ``range_noise_m``, log-normal spread
``range_noise_spread``); the intensity calibration spread (per-laser gains, spread
``intensity_gain_spread``) is applied to the remission (:mod:`generator.scan_effects.pipeline`).

Randomness: per-laser draws from ``stream(seed, "lidar_sensor", ...)``; the range noise of frame
``k`` from a key drawn from ``stream(seed, "frame", k, "lidar_returns")``, hashed per (beam, return)
into a standard normal (:mod:`generator.lidar.hashed_normal`), so a thread count or chunking never
changes a byte, and the strongest returns of a dual scan are the points of the strongest scan.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from generator.labels import class_table
from generator.materials import material_table
from generator.rng import stream

MODES = ("strongest", "dual")

#: cos of the angle between two faces' normals beyond which a merged return counts as mixed
MIXED_NORMAL_COS = math.cos(math.radians(30.0))


@dataclass(frozen=True)
class ReturnParams:
    """The ``returns`` block of a sensor table (units in the names; see the module docstring)."""

    model: str = "ideal"
    mode: str = "strongest"
    detection_threshold: float = 0.005
    divergence_mrad: float = 2.0
    subrays: int = 5
    separation_m: float = 0.75
    range_noise_m: float = 0.02
    range_noise_spread: float = 0.3
    intensity_gain_spread: float = 0.1
    glass_layers: int = 2
    edge_step: float = 0.05
    incidence_exponent: float = 0.25
    edge_subrays: str = "differing"

    @property
    def physical(self) -> bool:
        return self.model == "physical"

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class Optics:
    """Per-material optics at 905 nm, indexed by material id.

    Attributes
    ----------
    reflectivity : (M,) float32
        Diffuse reflectivity.
    lobe_gain, lobe_exponent : (M,) float32
        Retroreflective lobe (or the glint of glass): ``lobe_gain * cos^lobe_exponent`` added to ``cos``.
    transmittance : (M,) float32
        Share of the power a pane lets through, one way (0: opaque).
    smooth : (M,) bool
        Smooth surfaces (glass) whose diffuse term keeps Lambert's cosine.
    room : (M,) bool
        Panes with an unmodelled room behind them (``behind: room``): the beam ends there.
    cabin : (C,) bool, indexed by class id
        Classes whose panes close an unmodelled cabin (``cabins`` in ``materials.yaml``): the beam ends there.
    interior : (C,) bool, indexed by class id
        Classes whose cabin is modelled (``interiors`` in ``materials.yaml``): the beam goes on into the cabin
        and returns only from its own vehicle's opaque faces.
    reference_range_m, min_range_m : float
        ``R0`` of the normalisation and the range below which ``P`` stops growing.
    """

    reflectivity: np.ndarray
    lobe_gain: np.ndarray
    lobe_exponent: np.ndarray
    transmittance: np.ndarray
    smooth: np.ndarray
    room: np.ndarray
    cabin: np.ndarray
    interior: np.ndarray
    reference_range_m: float = 10.0
    min_range_m: float = 1.0


#: The specular glint of glass: half its peak at ~3.4 degrees off normal incidence.
GLASS_LOBE = (10.0, 400.0)
#: Diffuse back-scatter of a (dirty) pane of glass: a return within ~6 m at normal incidence.
GLASS_DIFFUSE = 0.002


def optics_from_materials(retro_gain: float = 20.0, retro_exponent: float = 8.0, reference_range_m: float = 10.0,
                          min_range_m: float = 1.0) -> Optics:
    """:class:`Optics` of ``generator/materials.yaml`` (the retro lobe constants are ``reflectivity.yaml``'s)."""
    mats = material_table()
    trans = mats.transmittance.astype(np.float32)
    # glass is smooth: what it does not let through it mirrors (the glint of the lobe); only a dirt film
    # scatters back diffusely (GLASS_DIFFUSE, Lambertian), enough for a return within a few metres
    refl = np.where(trans > 0, GLASS_DIFFUSE, mats.reflectivity).astype(np.float32)
    gain = np.where(mats.retro, retro_gain, np.where(trans > 0, GLASS_LOBE[0], 0.0)).astype(np.float32)
    expo = np.where(mats.retro, retro_exponent, np.where(trans > 0, GLASS_LOBE[1], 1.0)).astype(np.float32)
    classes = class_table()
    cabin = np.zeros(len(classes), bool)
    cabin[[classes.id(name) for name in mats.cabins]] = True
    interior = np.zeros(len(classes), bool)
    interior[[classes.id(name) for name in mats.interiors]] = True
    return Optics(refl, gain, expo, trans, trans > 0, mats.room_behind.copy(), cabin, interior,
                  float(reference_range_m), float(min_range_m))


def probe_index(pattern: np.ndarray, clockwise: bool) -> np.ndarray:
    """(4,) int64: the sub-ray looking towards each range-image neighbour: previous column, next column,
    ring above, ring below (a clockwise head fires its next column to the right of the beam)."""
    if len(pattern) == 0:
        return np.zeros(4, np.int64)
    ang = np.arctan2(pattern[:, 1], pattern[:, 0])
    nxt = 0.0 if not clockwise else np.pi
    want = np.array([np.pi - nxt, nxt, np.pi / 2, -np.pi / 2])
    gap = np.abs(np.mod(ang[None, :] - want[:, None] + np.pi, 2 * np.pi) - np.pi)
    return gap.argmin(1).astype(np.int64)


def subray_pattern(params: ReturnParams) -> np.ndarray:
    """(K - 1, 2) float64 angular offsets (radians) of the sub-rays round the centre, across the beam.

    The footprint is a Gaussian of 1/e^2 half-angle ``a = divergence / 2``; the centre stands for the
    disc holding ``1/K`` of the power, the others for equal sectors of the rest, each at the
    power-weighted mean radius of that annulus. The first points left (``+x``, horizontal across
    the beam), the others follow anticlockwise seen from the sensor (``+y`` up), so ``K = 5`` is a
    cross: left, up, right, down.
    """
    k = int(params.subrays)
    if k <= 1:
        return np.zeros((0, 2))
    a = params.divergence_mrad * 1e-3 / 2.0
    s_c = math.sqrt(-math.log(1.0 - 1.0 / k) / 2.0)  # disc radius holding 1/K of the power, in units of a
    s = np.linspace(s_c, 4.0, 4001)
    pdf = s * np.exp(-2.0 * s * s)
    radius = a * float(np.trapz(s * pdf, s) / np.trapz(pdf, s))
    phi = 2.0 * np.pi * np.arange(k - 1) / (k - 1)
    return radius * np.stack([np.cos(phi), np.sin(phi)], -1)


@dataclass
class ReturnModel:
    """Everything a scanner needs to decide a sweep's returns (built once per sequence).

    Attributes
    ----------
    params : ReturnParams
    optics : Optics
    pattern : (K - 1, 2) float64
        Sub-ray offsets, radians.
    ring_sigma : (L,) float32
        Range noise standard deviation per ring, metres.
    probes : (4,) int64
        Sub-ray towards each range-image neighbour (:func:`probe_index`).
    """

    params: ReturnParams
    optics: Optics
    pattern: np.ndarray
    ring_sigma: np.ndarray
    probes: np.ndarray

    def __post_init__(self):
        self.k_inc = self.incidence_exponents()

    @property
    def spread(self) -> float:
        """Largest angle of a sub-ray from its beam's centre, radians."""
        return float(np.hypot(*self.pattern.T).max()) if len(self.pattern) else 0.0

    @classmethod
    def build(cls, sensor, optics: Optics, seed: int) -> ReturnModel:
        """The model of ``sensor.returns`` for a dataset of ``seed`` (per-laser draws: ``("lidar_sensor", ...)``)."""
        p = sensor.returns
        sigma = laser_range_sigma(p, sensor.n_lasers, seed)
        ring_sigma = np.empty(sensor.n_lasers, np.float32)
        ring_sigma[sensor.ring] = sigma
        pattern = subray_pattern(p)
        return cls(p, optics, pattern, ring_sigma, probe_index(pattern, sensor.clockwise))

    def incidence_exponents(self) -> np.ndarray:
        """(M,) float32 ``k`` of each material's diffuse term ``cos^k`` (1 for smooth glass)."""
        return np.where(self.optics.smooth, 1.0, self.params.incidence_exponent).astype(np.float32)

    def describe(self) -> dict:
        """For ``lidar_meta.json``."""
        p = self.params
        return {
            **p.to_dict(),
            "power": "P = w tau rho (cos^k + lobe_gain cos^lobe_exponent) (R0 / max(R, R_min))^2 exp(-2 alpha R), "
                     "k = incidence_exponent (1 for glass); 1 = reflectivity-1 Lambertian target at R0 = 10 m, "
                     "normal incidence, clear air",
            "divergence_model": f"Gaussian footprint, {p.divergence_mrad} mrad full angle (1/e^2), {p.subrays} "
                                "sub-rays "
                                f"(centre + {max(p.subrays - 1, 0)} at {1e3 * self.spread:.3f} mrad, equal power) cast "
                                "where the beam and its range-image neighbours do not see one continuous surface "
                                "(a sub-ray that lands on the centre's own triangle, with nothing the neighbour on "
                                "its side sees able to stand in front of it, takes the centre's hit uncast)",
            "returns": "strongest: one point per beam; dual: strongest and last (second strongest when the strongest "
                       "is the last); returns nearer than separation_m merge (power-weighted range, dominant label)",
            "second_return_files": "dual only: second_return/velodyne/*.bin, second_return/labels/*.label (one point "
                                   "per "
                                   "second return) and second_return/first_index/*.bin (uint32 row of the same beam's "
                                   "first point in velodyne/*.bin); velodyne/ and labels/ hold one point per beam",
            "glass": "transmittance per material (materials.yaml); a beam that crossed an object's glass and meets "
                     "the same object again is absorbed (unmodelled interior); behind the glass of a modelled "
                     "cabin (interiors) it returns only from its own vehicle's opaque faces; facade glass "
                     "(behind: room) and unmodelled cabins (cabins) end the beam",
            "range_noise_sigma_m_per_laser": [round(float(s), 5) for s in self.ring_sigma[np.argsort(np.arange(
                len(self.ring_sigma)))]],
            "randomness": "per-laser draws: stream(seed, 'lidar_sensor', ...); per frame: stream(seed, 'frame', k, "
                          "'lidar_returns') keys a hash per (beam, return)",
        }


def laser_range_sigma(params: ReturnParams, n_lasers: int, seed: int) -> np.ndarray:
    """(L,) float32 range noise standard deviation of each table laser, metres (log-normal about ``range_noise_m``)."""
    g = stream(seed, "lidar_sensor", "range_noise")
    s = params.range_noise_spread
    return (params.range_noise_m * np.exp(s * g.standard_normal(n_lasers) - s * s / 2)).astype(np.float32)


def frame_key(seed: int, frame_index: int) -> int:
    """The 63-bit key of frame ``k``'s range noise (``stream(seed, "frame", k, "lidar_returns")``)."""
    return int(stream(seed, "frame", frame_index, "lidar_returns").integers(0, 2**63 - 1))
