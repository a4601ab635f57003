"""Which prototype meshes a scene's things are made of: distinct meshes per kind (issue 29).

A mesh is named by :func:`mesh_digest`, a hash of its vertices and faces, so the same prototype
built in two towns (or two processes) has one name and two different meshes never share one,
whatever their keys (``car_v3`` names another mesh in every re-drawn library). ``lidar_meta.json``
records the census of its sequence's world (``prototypes``); ``urbangen stats`` unites them over a
dataset (:mod:`generator.stats.assets`).
"""

from __future__ import annotations

import hashlib

import numpy as np

from generator.geometry import Mesh

DIGEST_HEX = 16     #: hex digits kept of the SHA-256 (64 bits: no collision among a dataset's meshes)


def mesh_digest(mesh: Mesh) -> str:
    """SHA-256 (first :data:`DIGEST_HEX` hex digits) of ``mesh``'s vertices (float64) and faces (int64)."""
    h = hashlib.sha256()
    h.update(np.ascontiguousarray(mesh.vertices, np.float64).tobytes())
    h.update(np.ascontiguousarray(mesh.faces, np.int64).tobytes())
    return h.hexdigest()[:DIGEST_HEX]


def prototype_census(scene, world=None) -> dict[str, dict]:
    """Objects and distinct meshes per kind of the static ``scene`` and the actors of ``world``.

    Parameters
    ----------
    scene : generator.world.scene.SceneModel
    world : generator.world.actors.World, optional
        Its actors count too (moving cars, walkers, riders).

    Returns
    -------
    dict
        ``{kind: {"objects": int, "meshes": sorted list of str}}``, kinds sorted; ``meshes`` are
        :func:`mesh_digest` names.
    """
    digests: dict[int, str] = {}

    def name(mesh: Mesh) -> str:
        if id(mesh) not in digests:
            digests[id(mesh)] = mesh_digest(mesh)
        return digests[id(mesh)]

    things = [(o.kind, scene.prototypes[o.prototype]) for o in scene.objects]
    if world is not None:
        things += [(a.kind, world.prototypes[a.prototype]) for a in world.actors]
    out: dict[str, dict] = {}
    for kind, mesh in things:
        entry = out.setdefault(kind, {"objects": 0, "meshes": set()})
        entry["objects"] += 1
        entry["meshes"].add(name(mesh))
    return {k: {"objects": v["objects"], "meshes": sorted(v["meshes"])} for k, v in sorted(out.items())}
