"""The hook that turns labelled points into remission values: ``remission = fn(points, rng)``.

An intensity function takes the scan's points (:data:`generator.lidar.scan.POINT_DTYPE`:
range, cos_incidence, class, material... are all there) and a ``numpy.random.Generator``
from the named stream ``("lidar", "intensity", frame)`` and returns (n,) float32 remission
in [0, 1]. The default is ``constant``: every point gets ``spec.lidar.constant_intensity``
(default 0.5, seed 000's fixed-value runs) -- a placeholder the sequence metadata says so.
``class_normal``, ``physical`` and ``hybrid`` are in :mod:`generator.lidar.intensity`.
Models register in :data:`INTENSITY_MODELS` by the names the spec's
``lidar.intensity_model`` enum uses.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from generator.errors import SpecError
from generator.lidar import intensity

IntensityFn = Callable[[np.ndarray, np.random.Generator], np.ndarray]


def constant(value: float = 0.5) -> IntensityFn:
    """An intensity function giving every point ``value``."""
    v = np.float32(value)

    def fn(points: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        return np.full(len(points), v, np.float32)

    fn.description = {"model": "constant", "value": float(value), "placeholder": True}
    return fn


#: Factories by spec name; each takes the spec and returns an :data:`IntensityFn`.
#: ``class_normal``, ``physical`` and ``hybrid`` live in :mod:`generator.lidar.intensity`.
INTENSITY_MODELS: dict[str, Callable[[object], IntensityFn]] = {
    "constant": lambda spec: constant(spec.lidar.constant_intensity),
    "class_normal": lambda spec: intensity.class_normal(intensity.profile_for_spec(spec)),
    "physical": lambda spec: intensity.physical(),
    "hybrid": lambda spec: intensity.hybrid(intensity.profile_for_spec(spec)),
}


def intensity_fn_for_spec(spec) -> IntensityFn:
    """The intensity function ``spec.lidar.intensity_model`` names.

    Raises
    ------
    SpecError
        If the model is not available (yet).
    """
    name = spec.lidar.intensity_model
    try:
        return INTENSITY_MODELS[name](spec)
    except KeyError:
        raise SpecError(spec.source or "spec", "lidar.intensity_model",
                        f"{name!r} is not available in this version (available: {', '.join(INTENSITY_MODELS)})") from None


#: Every model name, in the order the spec's enum lists them.
MODEL_NAMES = ("constant", "class_normal", "physical", "hybrid")


def intensity_model(name: str, profile: "intensity.IntensityProfile | None" = None, constant_value: float = 0.5,
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
        "class_normal": lambda: intensity.class_normal(profile or intensity.resolve_profile(None), label_space),
        "physical": intensity.physical,
        "hybrid": lambda: intensity.hybrid(profile or intensity.resolve_profile(None), label_space),
    }
    if name not in factories:
        raise SpecError("--intensity", "", f"unknown intensity model {name!r}; known: {', '.join(MODEL_NAMES)}")
    return factories[name]()
