"""Intensity (remission) models: constant, per-class normal profiles, physical received power, hybrid.

Every model is an :data:`IntensityFn` ``fn(points, rng) -> (n,) float32`` in [0, 1] and
carries a ``description`` dict that goes into ``lidar_meta.json``. ``points`` is a
structured array with at least ``range`` (metres) and ``cos_incidence`` and either

* ``class`` (native id) and ``material`` (material id): urbangen's own scans
  (:data:`generator.lidar.scan.POINT_DTYPE`), or
* ``semantic`` (SemanticKITTI raw id, uint16): imported data (CARLA frames), whose
  reflectivity comes from ``reflectivity.yaml``'s ``class_materials``.

Models
------
``class_normal``
    ``I ~ N(mean_c, std_c)`` clipped to [0, 1], with ``c`` the point's class in a profile
    (:class:`IntensityProfile`): its SemanticKITTI raw id if the profile has it, else its
    unified-11 class (seed 000 Table III is per unified class). Clipping piles the tails
    onto 0 and 1, so a wide class (traffic-sign, std 0.367) has a sample mean and std of
    the *censored* normal, not the profile's.
``physical``
    Normalised received power (see ``reflectivity.yaml``)::

        P = rho * (cos + g_retro * cos^p [retroreflective]) * (R0 / R)^2 * exp(-2 alpha0 R)

    relative to a reflectivity-1 Lambertian target at R0 = 10 m and normal incidence, then
    ``I = clip(P (1 + s_rel N) + s_abs N, 0, 1)``. alpha0 is clear air (0); the LiDAR
    weather multiplies by its own ``exp(-2 alpha R)`` later, so fog is not counted twice.
``hybrid``
    ``I = clip(x_c * w(cos, R), 0, 1)``, ``x_c`` the class-normal draw and ``w`` the
    incidence/range gain of ``reflectivity.yaml`` (1 at cos 0.5 and 15 m).
"""

from __future__ import annotations

import functools
import logging
from collections.abc import Callable
from pathlib import Path

import numpy as np

from generator.errors import SpecError
from generator.labels import class_table
from generator.materials import material_table
from generator.remission.class_profiles import LABEL_SPACES, IntensityProfile, profile_for_spec, resolve_profile
from generator.safeload import load_package_yaml

log = logging.getLogger(__name__)

IntensityFn = Callable[[np.ndarray, np.random.Generator], np.ndarray]
REFLECTIVITY_FILE = Path(__file__).resolve().parent / "reflectivity.yaml"


# -- per-point inputs -----------------------------------------------------------------------
@functools.cache
def reflectivity_config() -> dict:
    """``reflectivity.yaml`` with ``class_materials`` turned into (K,) reflectivity / retro lookups by raw id."""
    doc = load_package_yaml(REFLECTIVITY_FILE.read_text(encoding="utf-8"))
    mats = material_table()
    size = max(doc["class_materials"]) + 1
    refl = np.full(size, mats["default"].reflectivity, np.float32)
    retro = np.zeros(size, bool)
    for raw, name in doc["class_materials"].items():
        refl[int(raw)], retro[int(raw)] = mats[name].reflectivity, mats[name].retro
    doc["class_reflectivity"], doc["class_retro"] = refl, retro
    return doc


def semantic_ids(points: np.ndarray) -> np.ndarray:
    """(n,) uint16 SemanticKITTI raw ids: ``points['semantic']`` if present, else from the native ``class``."""
    if "semantic" in points.dtype.names:
        return np.asarray(points["semantic"], np.uint16)
    return class_table().to_semantickitti[points["class"]]


def surface_reflectivity(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(n,) float32 905 nm reflectivity and (n,) bool retroreflective flag of each point's surface.

    From the per-point ``material`` when there is one, else from the class (``class_materials``).
    """
    if "material" in points.dtype.names:
        mats = material_table()
        m = points["material"]
        return mats.reflectivity[m], mats.retro[m]
    cfg = reflectivity_config()
    raw = semantic_ids(points).astype(np.int64)
    raw = np.where(raw < len(cfg["class_reflectivity"]), raw, 0)
    return cfg["class_reflectivity"][raw], cfg["class_retro"][raw]


def received_power(points: np.ndarray, alpha_per_m: float | np.ndarray = 0.0) -> np.ndarray:
    """(n,) float64 normalised received power ``P`` of ``reflectivity.yaml`` (1 = rho 1 at R0, normal, clear).

    Parameters
    ----------
    points : (n,) structured
        Needs ``range`` (metres) and ``cos_incidence``, plus ``material`` or a class field.
    alpha_per_m : float or (n,) float
        Extinction coefficient, 1/m (two-way loss ``exp(-2 alpha R)``).
    """
    p = reflectivity_config()["physical"]
    rho, retro = surface_reflectivity(points)
    cos = np.clip(points["cos_incidence"].astype(np.float64), 0.0, 1.0)
    gain = cos + np.where(retro, p["retro_gain"] * cos ** p["retro_exponent"], 0.0)
    r = points["range"].astype(np.float64)
    spread = (p["reference_range_m"] / np.maximum(r, p["min_range_m"])) ** 2
    return rho * gain * spread * np.exp(-2.0 * np.asarray(alpha_per_m, np.float64) * r)


# -- models ---------------------------------------------------------------------------------
def _class_draw(profile: IntensityProfile, label_space: str):
    if label_space not in LABEL_SPACES:
        raise ValueError(f"label_space must be one of {LABEL_SPACES}, got {label_space!r}")
    mean, std, fallback = profile.raw_tables() if label_space == "semantickitti" else profile.unified_tables()
    if fallback:
        log.info("intensity profile %s has no entry for %s; using its 'unlabeled' (else 'pooled') entry",
                 profile.name, ", ".join(fallback))

    def draw(points: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        ids = semantic_ids(points).astype(np.int64)
        ids = np.where(ids < len(mean), ids, 0)  # ids the label set does not know are unlabeled
        return mean[ids] + std[ids] * rng.standard_normal(len(ids))

    desc = {"profile": profile.name, "profile_file": profile.file, "profile_source": profile.source,
            "label_space": label_space, "fallback": fallback}
    return draw, desc


def class_normal(profile: IntensityProfile, label_space: str = "semantickitti") -> IntensityFn:
    """Seed 000's statistical model: ``clip(N(mean_c, std_c), 0, 1)`` per point of class ``c``.

    Parameters
    ----------
    profile : IntensityProfile
    label_space : {'semantickitti', 'unified11'}
        What the points' ``semantic`` ids are (native points are always SemanticKITTI raw ids).
    """
    draw, desc = _class_draw(profile, label_space)

    def fn(points: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        return np.clip(draw(points, rng), 0.0, 1.0).astype(np.float32)

    fn.description = {"model": "class_normal", **desc, "clip": [0.0, 1.0]}
    return fn


def physical() -> IntensityFn:
    """Received power of the point's surface (``reflectivity.yaml``) with speckle-like noise, clipped to [0, 1]."""
    p = reflectivity_config()["physical"]

    def fn(points: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        power = received_power(points, p["clear_alpha_per_m"])
        noise = rng.standard_normal((2, len(points)))
        out = power * (1.0 + p["noise_relative"] * noise[0]) + p["noise_absolute"] * noise[1]
        return np.clip(out, 0.0, 1.0).astype(np.float32)

    fn.description = {
        "model": "physical",
        "formula": "clip(P * (1 + noise_relative N) + noise_absolute N, 0, 1); "
                   "P = rho (cos + retro_gain cos^retro_exponent [retroreflective]) "
                   "(R0 / max(R, min_range_m))^2 exp(-2 clear_alpha R)",
        "normalisation": "P = 1 for a reflectivity-1 Lambertian target at R0 and normal incidence in clear air",
        "reflectivity": "generator/materials.yaml at 905 nm "
                        "(per point material, else class_materials of reflectivity.yaml)",
        **{k: float(v) for k, v in p.items()},
    }
    return fn


def hybrid(profile: IntensityProfile, label_space: str = "semantickitti") -> IntensityFn:
    """Class-normal draw times the incidence/range gain ``w`` of ``reflectivity.yaml``, clipped to [0, 1]."""
    h = reflectivity_config()["hybrid"]
    draw, desc = _class_draw(profile, label_space)
    a = h["incidence_weight"]

    def fn(points: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        cos = np.clip(points["cos_incidence"].astype(np.float64), 0.0, 1.0)
        r = np.maximum(points["range"].astype(np.float64), h["min_range_m"])
        w = (
            ((1 - a) + a * cos)
            / ((1 - a) + a * h["reference_cos"])
            * (h["reference_range_m"] / r) ** h["range_exponent"]
        )
        return np.clip(draw(points, rng) * np.minimum(w, h["max_gain"]), 0.0, 1.0).astype(np.float32)

    fn.description = {
        "model": "hybrid",
        **desc,
        "formula": "clip(N(mean_c, std_c) * min(max_gain, ((1-a) + a cos) / ((1-a) + a reference_cos) "
        "* (reference_range_m / max(R, min_range_m))^range_exponent), 0, 1), a = incidence_weight",
        **{k: float(v) for k, v in h.items()},
    }
    return fn


def constant(value: float = 0.5) -> IntensityFn:
    """An intensity function giving every point ``value``."""
    v = np.float32(value)

    def fn(points: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        return np.full(len(points), v, np.float32)

    fn.description = {"model": "constant", "value": float(value), "placeholder": True}
    return fn


#: Factories by spec name; each takes the spec (and a command-line profile, or None) and returns an
#: :data:`IntensityFn`.
#: ``class_normal``, ``physical`` and ``hybrid`` live in :mod:`generator.remission.models`.
INTENSITY_MODELS: dict[str, Callable[..., IntensityFn]] = {
    "constant": lambda spec, profile=None: constant(spec.lidar.constant_intensity),
    "class_normal": lambda spec, profile=None: class_normal(profile_for_spec(spec, profile)),
    "physical": lambda spec, profile=None: physical(),
    "hybrid": lambda spec, profile=None: hybrid(profile_for_spec(spec, profile)),
}


def intensity_fn_for_spec(spec, command_line_profile: str | None = None) -> IntensityFn:
    """The intensity function ``spec.lidar.intensity_model`` names.

    Parameters
    ----------
    command_line_profile : str, optional
        A profile named on the command line (a shipped name or a path taken as given),
        used instead of ``spec.lidar.intensity_profile`` (which stays inside the spec's folder).

    Raises
    ------
    SpecError
        If the model is not available (yet).
    """
    name = spec.lidar.intensity_model
    if name not in INTENSITY_MODELS:
        raise SpecError(spec.source or "spec", "lidar.intensity_model",
                        f"{name!r} is not available in this version (available: {', '.join(INTENSITY_MODELS)})")
    return INTENSITY_MODELS[name](spec, command_line_profile)


#: Every model name, in the order the spec's enum lists them.
MODEL_NAMES = ("constant", "class_normal", "physical", "hybrid")


def intensity_model(name: str, profile: IntensityProfile | None = None, constant_value: float = 0.5,
                    label_space: str = "semantickitti") -> IntensityFn:
    """An intensity function by model name, without a spec (importers, converters).

    Parameters
    ----------
    name : str
        One of :data:`MODEL_NAMES`.
    profile : IntensityProfile, optional
        For ``class_normal`` / ``hybrid`` (default: seed 000 Table III).
    constant_value : float
        For ``constant``.
    label_space : {'semantickitti', 'unified11'}
        What the points' ``semantic`` ids are, for the profile lookup.
    """
    factories = {
        "constant": lambda: constant(constant_value),
        "class_normal": lambda: class_normal(profile or resolve_profile(None), label_space),
        "physical": physical,
        "hybrid": lambda: hybrid(profile or resolve_profile(None), label_space),
    }
    if name not in factories:
        raise SpecError("--intensity", "", f"unknown intensity model {name!r}; known: {', '.join(MODEL_NAMES)}")
    return factories[name]()
