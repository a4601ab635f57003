"""World actors -> Blender objects posed at any time.

Each actor prototype becomes one Blender mesh (the same code, materials and per-face
``class_id`` as the static town's prototypes, so the label passes treat actors like any
object); each actor one object in the real collection (its label hull, if it has one, in the
proxy collection) with ``pass_index`` = ``actor.instance_id``. Poses come from
``actor.track`` through linear keys (:mod:`generator.blender.motion`): the image instant on
the middle key, the shutter's opening and closing on the outer ones. A moving vehicle's
headlights (its prototype's ``headlight`` anchors) are spot lights parented to its object,
so they drive with it; they are switched with the other night lights.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from generator.blender import geometry, motion
from generator.blender.bpy_guard import bpy
from generator.world.actors import World

log = logging.getLogger(__name__)


@dataclass
class ActorObjects:
    """What :func:`build` created.

    Attributes
    ----------
    world : World
    keys : list of motion.Keys
        One per posed object (real objects and hulls).
    owners : list of int
        Index into ``world.actors`` of each entry of ``keys``.
    objects : list of bpy.types.Object
        The real object of each actor, in ``world.actors`` order.
    meshes : dict of str to bpy.types.Mesh
        The Blender mesh of every prototype key used (a walker's gait phase meshes among them).
    """

    world: World
    keys: list
    owners: list
    objects: list
    meshes: dict | None = None

    def pose(self, times: np.ndarray) -> None:
        """Key every actor at ``times`` = (opening, instant, closing), seconds on the world's timeline; a
        walker shows the gait phase mesh of the instant (the one the LiDAR meets then)."""
        times = np.asarray(times, np.float64)
        values = [motion.yaw_values(a.track.position(times), a.track.heading(times)) for a in self.world.actors]
        for keys, owner in zip(self.keys, self.owners, strict=False):
            keys.set(values[owner])
        for a, ob in zip(self.world.actors, self.objects, strict=True):
            if a.gait is not None:
                mesh = self.meshes[a.prototype_at(float(times[len(times) // 2]))]
                if ob.data is not mesh:
                    ob.data = mesh


def build(world: World, materials: list, handles: geometry.BlenderScene) -> ActorObjects:
    """Create the objects of ``world.actors``.

    Parameters
    ----------
    world : World
    materials : list of bpy.types.Material
        Indexed by material id.
    handles : geometry.BlenderScene
        The static town's collections; actor hulls are appended to ``handles.proxy_objects``
        (so they are shown and hidden with the town's).
    """
    used = sorted({a.prototype for a in world.actors} | {k for a in world.actors if a.gait for k in a.gait.keys})
    meshes = {key: geometry.mesh("actor:" + key, world.prototypes[key], materials) for key in used}
    hull_keys = sorted({a.proxy for a in world.actors if a.proxy is not None})
    hull_meshes = {key: geometry.mesh("actor_hull:" + key, world.proxies[key], materials) for key in hull_keys}
    keys, owners, objects = [], [], []
    for i, a in enumerate(world.actors):
        ob = geometry.new_object(a.name, meshes[a.prototype], np.eye(4), a.instance_id, a.cls, a.attrs)
        handles.real.objects.link(ob)
        objects.append(ob)
        keys.append(motion.Keys(ob))
        owners.append(i)
        if a.proxy is not None:
            hb = geometry.new_object(a.name + "_hull", hull_meshes[a.proxy], np.eye(4), a.instance_id)
            handles.proxies.objects.link(hb)
            handles.proxy_objects.append(hb)
            keys.append(motion.Keys(hb))
            owners.append(i)
    log.info("%d actors from %d prototypes in the Blender scene", len(world.actors), len(meshes))
    return ActorObjects(world, keys, owners, objects, meshes)


def headlights(objs: ActorObjects, make_spot, collection: bpy.types.Collection) -> int:
    """Spot lights at every actor's ``headlight`` anchors, parented to its object; return how many.

    ``make_spot(name, location, direction, collection) -> bpy.types.Object`` creates one light
    (local frame of the actor: location metres, direction a vector).
    """
    n = 0
    for a, ob in zip(objs.world.actors, objs.objects, strict=False):
        anchors = objs.world.prototypes[a.prototype].anchors
        for p in anchors.get("headlight", ()):
            light = make_spot(f"{a.name}_headlight", p, (1.0, 0.0, -0.12), collection)
            light.parent = ob
            n += 1
    return n
