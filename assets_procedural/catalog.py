"""One entry point for every asset family: ``build(kind, rng, **params)``.

The layout names what it needs by kind; this table maps the kind to its builder and to
the native class that identifies the object (instance boxes, statistics).
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from assets_procedural.building import building
from assets_procedural.fence import fence
from generator.geometry import Mesh
from assets_procedural.person import person
from assets_procedural.street_furniture import lamp_post, traffic_light, traffic_sign
from assets_procedural.vegetation import bush, hedge, tree
from assets_procedural.vehicle import car, truck

BUILDERS: dict[str, Callable[..., Mesh]] = {
    "building": building,
    "tree": tree,
    "bush": bush,
    "hedge": hedge,
    "lamp_post": lamp_post,
    "traffic_light": traffic_light,
    "traffic_sign": traffic_sign,
    "fence": fence,
    "car": car,
    "truck": truck,
    "person": person,
}

KINDS: tuple[str, ...] = tuple(BUILDERS)

#: kind -> the native class name of the object's main part
MAIN_CLASS: dict[str, str] = {
    "building": "building",
    "tree": "tree_crown",
    "bush": "vegetation",
    "hedge": "vegetation",
    "lamp_post": "pole",
    "traffic_light": "traffic_light",
    "traffic_sign": "traffic_sign",
    "fence": "fence",
    "car": "car",
    "truck": "truck",
    "person": "person",
}


def build(kind: str, rng: np.random.Generator, **params) -> Mesh:
    """Build one asset of ``kind`` in its local frame.

    Parameters
    ----------
    kind : str
        One of :data:`KINDS`.
    rng : numpy.random.Generator
        The only source of randomness; the same state gives identical arrays.
    **params
        Forwarded to the family builder (e.g. ``height`` for trees, ``footprint`` for
        buildings); see each builder's docstring.

    Raises
    ------
    KeyError
        For an unknown kind (the message lists the known ones).
    """
    try:
        builder = BUILDERS[kind]
    except KeyError:
        raise KeyError(f"unknown asset kind {kind!r}; known: {', '.join(KINDS)}") from None
    return builder(rng, **params)
