"""The hook that turns labelled points into remission values: ``remission = fn(points, rng)``.

An intensity function takes the scan's points (:data:`generator.lidar.scan.POINT_DTYPE`:
range, cos_incidence, class, material... are all there) and a ``numpy.random.Generator``
from the named stream ``("lidar", "intensity", frame)`` and returns (n,) float32 remission
in [0, 1]. Until the intensity models land, the only one is ``constant``: every point
gets ``spec.lidar.constant_intensity`` (default 0.5) -- a placeholder the sequence
metadata says so. Models register in :data:`INTENSITY_MODELS` by the names the spec's
``lidar.intensity_model`` enum uses.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from generator.errors import SpecError

IntensityFn = Callable[[np.ndarray, np.random.Generator], np.ndarray]


def constant(value: float = 0.5) -> IntensityFn:
    """An intensity function giving every point ``value``."""
    v = np.float32(value)

    def fn(points: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        return np.full(len(points), v, np.float32)

    fn.description = {"model": "constant", "value": float(value), "placeholder": True}
    return fn


#: Factories by spec name; each takes the spec and returns an :data:`IntensityFn`.
INTENSITY_MODELS: dict[str, Callable[[object], IntensityFn]] = {
    "constant": lambda spec: constant(spec.lidar.constant_intensity),
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
