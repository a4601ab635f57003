"""How many prototypes of each instanced kind a town's library holds, and who the people are.

Issue 29: a town used to hold six car meshes and six people. The counts now come from the spec
(``assets.variants``, defaults 48 cars and 48 people) and every variant is drawn with its own
parameters:

* **cars** -- variant ``i`` of ``n`` asks the car builder for the body type at the quantile
  ``(i + 0.5) / n`` of the fleet shares (``assets_procedural.vehicle.CAR_VARIANTS``), so a
  library of ``n`` cars holds each body type in its share (largest deviation one car) and a town
  that picks variants uniformly parks and drives that mix; the dimensions within a body type are
  drawn by the builder from each type's range of real models;
* **people** -- :func:`draw_figure`: the share ``assets.child_share`` of the variants are children
  aged 4-14 (every variant ``i`` where ``floor((i + 1) * share)`` steps up: spread evenly over the
  standing and the walking half) with the WHO growth reference's median height for their age (a 4.5 %
  spread), the rest adults, half women and half men (drawn), heights from the sex's normal
  distribution clipped to ``heights.person_m``; the
  builder gives children bigger heads for their height (``age``) and men broader shoulders (``sex``).

Parked, standing, walking and driving things draw on the same variants, so a car that parks and one
that drives can share a mesh, and the traffic's widest vehicle is one of the library's.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from generator.layout.placement.prototypes import Library, Proto
from generator.spec.model import SceneSpec

#: variants per kind when the library has no count for it (a bare ``Library(seed)``: benches, tests)
DEFAULT_COUNTS = {"car": 6, "person": 6, "truck": 3}

#: WHO growth reference 2007 (5-19 years) and child growth standards (< 5 years), median height
#: for age, boys and girls averaged: age (years) -> metres
WHO_AGE = (4.0, 5.0, 6.0, 8.0, 10.0, 12.0, 14.0)
WHO_HEIGHT_M = (1.027, 1.099, 1.160, 1.276, 1.384, 1.505, 1.614)
CHILD_SPREAD = 0.045      #: relative standard deviation of a child's height about the median for its age
#: adult heights (metres): mean and standard deviation by sex, European adults born 1980-1996
#: (NCD-RisC 2016, eLife 5:e13410, rounded): women 1.65 +- 0.065, men 1.78 +- 0.07
ADULT_HEIGHT_M = {"female": (1.65, 0.065), "male": (1.78, 0.07)}


def variant_counts(spec: SceneSpec) -> dict[str, int]:
    """``{kind: variants}`` of the spec's ``assets.variants`` (for :class:`Library`)."""
    return dataclasses.asdict(spec.assets.variants)


def car_variant(lib: Library, i: int) -> Proto:
    """Car variant ``i`` (modulo the library's car count), its body type at the quantile ``(i + 0.5) / n``."""
    n = lib.count("car", DEFAULT_COUNTS["car"])
    i = int(i) % n
    return lib.variant("car", i, lambda g: {"quantile": (i + 0.5) / n})


def truck_variant(lib: Library, i: int) -> Proto:
    """Truck variant ``i`` (modulo the library's truck count)."""
    return lib.variant("truck", int(i) % lib.count("truck", DEFAULT_COUNTS["truck"]))


def is_child(i: int, share: float) -> bool:
    """Whether person variant ``i`` is a child: ``floor((i + 1) * share) > floor(i * share)``."""
    return int(np.floor((i + 1) * share + 1e-9)) > int(np.floor(i * share + 1e-9))


def draw_figure(g: np.random.Generator, adult_m: tuple[float, float], child: bool) -> dict:
    """One person's ``height`` (metres), ``age`` (years) and ``sex`` (see the module docstring).

    Parameters
    ----------
    g : numpy.random.Generator
        The variant's own stream (three draws, whatever comes out).
    adult_m : (low, high)
        Adult heights are clipped to this range (the spec's ``heights.person_m``).
    child : bool
        A child (4-14 years) or an adult (18-80).
    """
    sex = "female" if g.random() < 0.5 else "male"
    z = float(g.standard_normal())
    if child:
        age = float(g.uniform(4.0, 14.0))
        height = float(np.interp(age, WHO_AGE, WHO_HEIGHT_M)) * (1.0 + CHILD_SPREAD * z)
        return {"height": float(np.clip(height, 0.95, 1.85)), "age": age, "sex": sex}
    mean, sd = ADULT_HEIGHT_M[sex]
    age = float(g.uniform(18.0, 80.0))
    return {"height": float(np.clip(mean + sd * z, *adult_m)), "age": age, "sex": sex}


def person_variants(lib: Library, spec: SceneSpec) -> list[Proto]:
    """The town's person variants: the first half standing, the rest walking."""
    n = lib.count("person", DEFAULT_COUNTS["person"])
    lo, hi = spec.heights.person_m
    share = spec.assets.child_share

    def params(g, i):
        return {**draw_figure(g, (lo, hi), is_child(i, share)), "pose": "standing" if i < n // 2 else "walking"}

    return [lib.variant("person", i, lambda g, i=i: params(g, i)) for i in range(n)]
