"""The things of the world that get a 3D box: parked statics of the scene and moving actors.

A :class:`Subject` is one detection object for the whole sequence: a stable ``track_id``, the
instance ids its points and pixels carry, its box class (``generator/labels/detection.yaml``) and
its geometry at any time. A ridden two-wheeler is one subject holding vehicle and rider: a moving
one is one actor (one instance); a static one is two placed objects (the vehicle, then its rider
placed on it under the same transform, two instance ids) that are paired here.

Frames: world frame (z up, metres); boxes are :class:`generator.world.scene.OrientedBox`
(centre, length/width/height, yaw about +z).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np

from generator.labels.detection import detection_classes
from generator.world.actors import MOVING_THRESHOLD_MPS
from generator.world.scene import OrientedBox

log = logging.getLogger(__name__)

#: Placements of static vehicles that stand with a driver meaning to move on (nuScenes
#: ``vehicle.stopped``); every other static vehicle is ``vehicle.parked``.
STOPPED_PLACEMENTS = frozenset({"lane", "bus_stop", "tram_stop"})


@dataclass(frozen=True)
class Part:
    """One mesh of a subject under a pose that may change with time.

    Attributes
    ----------
    mesh : generator.geometry.Mesh or None
        Local frame (x forward, y left, z up), metres (None: a box without geometry, as in tests).
    transform : (4, 4) float64 or None
        ``T_world_local`` of a static part; None for an actor (pose from ``track``).
    track : generator.world.actors.Track or None
    actor : generator.world.actors.Actor or None
        An articulated actor (a walker) whose mesh changes with time; ``meshes`` then holds the
        world's prototypes it picks from (:meth:`mesh_at`).
    meshes : dict of str to Mesh or None
    """

    mesh: object
    transform: np.ndarray | None = None
    track: object = None
    actor: object = None
    meshes: dict | None = None

    def mesh_at(self, t: float):
        """The mesh at ``t`` seconds: a walker's gait phase mesh then, else :attr:`mesh`."""
        if self.actor is None or self.actor.gait is None:
            return self.mesh
        return self.meshes[self.actor.prototype_at(t)]

    def pose(self, t: float) -> np.ndarray:
        """(4, 4) float64 ``T_world_local`` at ``t`` seconds."""
        return self.transform if self.track is None else self.track.pose(t)[0]


@dataclass(frozen=True)
class Subject:
    """One boxed thing of the world, for the whole sequence.

    Attributes
    ----------
    track_id : int
        Stable id: the instance id of the object naming the box (an actor's, a static rider's).
    instance_ids : tuple of int
        Every instance id whose points and pixels belong to the box (vehicle and rider).
    cls : str
        Box class (a native thing class, ``detection.yaml``).
    kind : str
        Asset kind of the object naming the box (``"car"``, ``"box_van"``, ``"bicyclist"``...).
    name : str
        Scene object or actor name.
    static : bool
        Part of the static town (no track).
    group : str
        nuScenes attribute family: ``vehicle``, ``cycle``, ``pedestrian``.
    with_rider : bool
        A ridden two-wheeler (``cycle.with_rider``).
    placement : str
        Where a static object was placed (``"parked"``, ``"lane"``...), ``""`` for actors.
    parts : tuple of Part
    """

    track_id: int
    instance_ids: tuple[int, ...]
    cls: str
    kind: str
    name: str
    static: bool
    group: str
    with_rider: bool
    placement: str
    parts: tuple[Part, ...] = field(repr=False)
    _static_box: OrientedBox | None = field(default=None, repr=False)
    _actor: object = field(default=None, repr=False)

    def box(self, t: float) -> OrientedBox:
        """The box at ``t`` seconds, world frame."""
        return self._static_box if self._actor is None else self._actor.box(t)

    def motion(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """(velocity, acceleration) (3,) float64 of the box centre over ground at ``t``, world frame,
        m/s and m/s^2: central differences over the track's sample spacing (zero for statics)."""
        if self._actor is None:
            return np.zeros(3), np.zeros(3)
        h = self._actor.track.dt
        c = [self._actor.rigid_center(t + d) for d in (-h, 0.0, h)]   # a walker's limbs do not move its box
        return (c[2] - c[0]) / (2 * h), (c[2] - 2 * c[1] + c[0]) / (h * h)

    def moving(self, t: float) -> bool:
        """Faster than :data:`MOVING_THRESHOLD_MPS` at ``t`` (the rule of the LiDAR moving-* ids)."""
        return self._actor is not None and bool(self._actor.track.speed(t)[0] > MOVING_THRESHOLD_MPS)

    def attribute(self, t: float) -> str:
        """The nuScenes attribute at ``t``: ``vehicle.moving|stopped|parked``,
        ``cycle.with_rider|without_rider`` or ``pedestrian.moving|standing``."""
        if self.group == "cycle":
            return "cycle.with_rider" if self.with_rider else "cycle.without_rider"
        if self.group == "pedestrian":
            return "pedestrian.moving" if self.moving(t) else "pedestrian.standing"
        if self.moving(t):
            return "vehicle.moving"
        return "vehicle.stopped" if not self.static or self.placement in STOPPED_PLACEMENTS else "vehicle.parked"

    def triangles(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """The subject's real triangles at ``t``: (V, 3) float64 world vertices, (F, 3) int64 faces."""
        verts, faces, off = [], [], 0
        for p in self.parts:
            T = p.pose(t)
            mesh = p.mesh_at(t)
            v = np.asarray(mesh.vertices, np.float64)
            verts.append(v @ T[:3, :3].T + T[:3, 3])
            faces.append(np.asarray(mesh.faces, np.int64) + off)
            off += len(v)
        return np.concatenate(verts), np.concatenate(faces)


def union_box(boxes: list[OrientedBox], yaw: float) -> OrientedBox:
    """The smallest box turned by ``yaw`` holding every box of ``boxes`` (world frame)."""
    c, s = np.cos(yaw), np.sin(yaw)
    R = np.array([[c, -s], [s, c]])
    xy = np.vstack([b.corners_xy() for b in boxes]) @ R          # into the yaw frame
    z0 = min(b.center[2] - b.size[2] / 2 for b in boxes)
    z1 = max(b.center[2] + b.size[2] / 2 for b in boxes)
    lo, hi = xy.min(0), xy.max(0)
    cxy = R @ ((lo + hi) / 2)
    return OrientedBox((float(cxy[0]), float(cxy[1]), (z0 + z1) / 2), (float(hi[0] - lo[0]), float(hi[1] - lo[1]),
                                                                        z1 - z0), float(yaw))


def _static_subjects(scene) -> list[Subject]:
    dc = detection_classes()
    part_of = dc.part_of
    objs = [o for o in scene.objects if o.instance_id > 0 and (o.cls in dc.boxes or o.cls in part_of)]
    riders = {o.index for o in objs if o.cls in dc.boxes and dc.boxes[o.cls].parts}
    spare = {o.index: o for o in objs if o.cls in part_of}
    out = []
    for o in objs:
        if o.cls in part_of:
            continue
        b = dc.boxes[o.cls]
        members = [o]
        if o.index in riders:  # the vehicle it sits on: a part of its box class under the same transform
            match = [v for v in spare.values() if part_of[v.cls] == o.cls and np.allclose(v.transform, o.transform)]
            if match:
                members.append(spare.pop(match[0].index))
        box = union_box([m.box for m in members], o.box.yaw) if len(members) > 1 else o.box
        out.append(Subject(o.instance_id, tuple(m.instance_id for m in members), o.cls, o.kind, o.name, True, b.group,
                           bool(b.parts) and len(members) > 1, str(o.attrs.get("placement", "")),
                           tuple(Part(scene.prototypes.get(m.prototype), np.asarray(m.transform, np.float64))
                                 for m in members), box))
    for v in spare.values():  # a ridden vehicle without its rider (none is placed so): boxed alone, riderless
        cls = part_of[v.cls]
        log.warning("%s: ridden vehicle without a rider; boxed alone", v.name)
        part = Part(scene.prototypes.get(v.prototype), np.asarray(v.transform, np.float64))
        out.append(Subject(v.instance_id, (v.instance_id,), cls, v.kind, v.name, True, dc.boxes[cls].group, False,
                           str(v.attrs.get("placement", "")), (part,), v.box))
    return out


def _actor_subjects(world) -> list[Subject]:
    dc = detection_classes()
    out = []
    for a in world.actors:
        cls = dc.part_of.get(a.cls, a.cls)
        if cls not in dc.boxes:
            continue
        b = dc.boxes[cls]
        out.append(Subject(a.instance_id, (a.instance_id,), cls, a.kind, a.name, False, b.group, bool(b.parts), "",
                           (Part(world.prototypes.get(a.prototype), None, a.track, a, world.prototypes),), None, a))
    return out


def subjects(scene, world=None) -> list[Subject]:
    """Every boxed thing of ``scene`` (static) and ``world`` (actors), sorted by ``track_id``.

    Parameters
    ----------
    scene : generator.world.scene.SceneModel
    world : generator.world.actors.World, optional
        The world in time; without it (or without actors) only the static town is boxed.
    """
    out = _static_subjects(scene) + (_actor_subjects(world) if world is not None else [])
    ids = [s.track_id for s in out]
    if len(set(ids)) != len(ids):
        raise ValueError("two boxed things share a track id (an instance id)")
    return sorted(out, key=lambda s: s.track_id)
