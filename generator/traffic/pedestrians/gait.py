"""A walking prototype's gait cycle, as the world's phase meshes (:class:`generator.world.actors.Gait`).

A walking person model (:mod:`assets_procedural.person`) carries its cycle as anchors: ``gait/NN``, the
vertices at phase ``NN / n`` (the faces are the model's), and ``gait/stride``, two points one stride
(metres walked per cycle) apart.
"""

from __future__ import annotations

import numpy as np

from generator.geometry import Mesh
from generator.world.actors import Gait


def gait_cycle(key: str, mesh, prototypes: dict) -> tuple | None:
    """A walking prototype's gait cycle: its phase meshes added to ``prototypes`` (keys ``key@gNN``).

    Returns
    -------
    (keys, stride_m, lo, hi) or None
        Phase mesh keys, metres per cycle, (n, 3) local bounds per phase; None for a mesh without a
        cycle (its ``gait/NN`` anchors, :mod:`assets_procedural.person`).
    """
    names = sorted(k for k in mesh.anchors if k.startswith("gait/") and k[5:].isdigit())
    if not names:
        return None
    keys, lo, hi = [], [], []
    for name in names:
        v = mesh.anchors[name]
        k = f"{key}@g{name[5:]}"
        prototypes[k] = Mesh(v, mesh.faces, mesh.face_class, mesh.face_material)
        keys.append(k)
        lo.append(v.min(0))
        hi.append(v.max(0))
    ends = mesh.anchors["gait/stride"]
    return tuple(keys), float(np.linalg.norm(ends[1] - ends[0])), np.array(lo), np.array(hi)


def walker_gait(key: str, mesh, track, prototypes: dict, cycles: dict) -> Gait | None:
    """The :class:`Gait` of a walker on ``track`` (:class:`generator.world.actors.Track`) showing prototype ``key``
    (``mesh``), or None for a mesh without a cycle; ``cycles`` keeps :func:`gait_cycle` per key between walkers."""
    if key not in cycles:
        cycles[key] = gait_cycle(key, mesh, prototypes)
    if cycles[key] is None:
        return None
    keys, stride, lo, hi = cycles[key]
    return Gait(keys, stride, Gait.walked(track), lo, hi)
