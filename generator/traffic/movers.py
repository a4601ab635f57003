"""What every traffic simulation hands to :func:`generator.traffic.build.build_world`.

A :class:`Mover` is a prototype (from the layout's asset :class:`~generator.layout.placement.prototypes.Library`,
so the same meshes the static town uses) plus its sampled :class:`~generator.world.actors.Track`.
A ridden two-wheeler is one mover whose prototype is the rider and the vehicle merged (one
instance, as SemanticKITTI labels a bicyclist with the bicycle).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from generator.world.actors import Track

#: Simulation step of every traffic model, seconds (tracks are sampled at this spacing).
DT_S = 0.05


@dataclass
class Mover:
    """One simulated actor before ids are assigned.

    Attributes
    ----------
    kind : str
        Asset kind (``"car"``, ``"person"``, ``"ridden_bicycle"`` ...).
    cls : str
        Main native class (``"car"``, ``"person"``, ``"bicyclist"`` ...).
    proto : generator.layout.placement.prototypes.Proto
        Prototype (mesh in the local frame: x forward, y left, z up, origin on the ground).
    track : Track
        Pose of the local origin every :data:`DT_S` seconds from t = 0.
    attrs : dict
        Renderer parameters (``color``) and ``role`` (``"walking"``, ``"standing"``, ``"driving"``).
    """

    kind: str
    cls: str
    proto: object
    track: Track
    attrs: dict = field(default_factory=dict)
