"""Poses in time for Cycles: objects keyed at the shutter's opening, the image instant and its closing.

Frame mapping: scene frame :data:`FRAME` is the image instant ``t``; frames ``FRAME - 1`` and
``FRAME + 1`` are ``t - shutter/2`` and ``t + shutter/2``. Every moving object (actors, their
label hulls, the camera when motion blur is on) carries six linear F-curves (location x, y, z,
rotation_euler x, y, z) with one key on each of those three frames, so

* a render at :data:`FRAME` without motion blur (the label passes, a config with blur off) sees
  every object exactly at ``t``;
* Cycles' motion blur with a shutter of :data:`SHUTTER_FRAMES` centred on :data:`FRAME` integrates
  the poses from ``t - shutter/2`` to ``t + shutter/2``; between the keys a pose is linear in time,
  as :class:`generator.world.actors.Track` is between its samples (50 ms apart, longer than any
  shutter), so the blur follows the track exactly unless a sample falls inside the exposure;
* Cycles' vector pass (motion to frames ``FRAME -/+ 1``) measures the same displacement.

Keys are rewritten in place with ``foreach_set`` for each image: no operator, no new datablock.
Blender 5.0 actions are layered: one action per object with one slot, one layer, one keyframe
strip and its channel bag.
"""

from __future__ import annotations

import numpy as np

from generator.blender.bpy_guard import bpy

#: Scene frame of the image instant; its neighbours are the shutter's opening and closing.
FRAME = 1
#: Key frames: opening, instant, closing.
KEY_FRAMES = np.array([FRAME - 1, FRAME, FRAME + 1], np.float32)
#: Cycles shutter length in frames (``render.motion_blur_shutter``), centred on :data:`FRAME`.
SHUTTER_FRAMES = 2.0
#: Key values per time: location x, y, z and rotation_euler x, y, z.
CHANNELS = (("location", 0), ("location", 1), ("location", 2),
            ("rotation_euler", 0), ("rotation_euler", 1), ("rotation_euler", 2))
ACTION_PREFIX = "ug_motion:"
#: An object in no scene, used to decompose poses the way Blender does.
SCRATCH = "ug_motion_scratch"
_LINEAR = bpy.types.Keyframe.bl_rna.properties["interpolation"].enum_items["LINEAR"].value


class Keys:
    """The six linear F-curves of one object, three keys each.

    Parameters
    ----------
    ob : bpy.types.Object
        Keeps the motion action it already has (from an earlier :class:`Keys`), else gets a new
        one (replacing any other animation).
    """

    def __init__(self, ob: bpy.types.Object):
        self.object = ob
        ad = ob.animation_data
        if ad is not None and ad.action is not None and ad.action.name.startswith(ACTION_PREFIX):
            self.fcurves = list(ad.action.layers[0].strips[0].channelbag(ad.action_slot).fcurves)
            return
        action = bpy.data.actions.new(ACTION_PREFIX + ob.name)
        slot = action.slots.new(id_type="OBJECT", name=ob.name)
        bag = action.layers.new("motion").strips.new(type="KEYFRAME").channelbag(slot, ensure=True)
        self.fcurves = []
        for path, index in CHANNELS:
            fc = bag.fcurves.new(path, index=index)
            fc.keyframe_points.add(len(KEY_FRAMES))
            fc.keyframe_points.foreach_set("interpolation", np.full(len(KEY_FRAMES), _LINEAR, np.int32))
            self.fcurves.append(fc)
        ad = ob.animation_data_create()
        ad.action = action
        ad.action_slot = slot

    @staticmethod
    def present(ob: bpy.types.Object) -> bool:
        """Whether ``ob`` carries motion keys."""
        ad = ob.animation_data
        return ad is not None and ad.action is not None and ad.action.name.startswith(ACTION_PREFIX)

    def set(self, values: np.ndarray) -> None:
        """Rewrite the keys.

        Parameters
        ----------
        values : (3, 6) float
            Per key frame (opening, instant, closing): location (metres, world) and XYZ Euler
            rotation (radians, continuous from key to key).
        """
        values = np.asarray(values, np.float32)
        co = np.empty((len(KEY_FRAMES), 2), np.float32)
        co[:, 0] = KEY_FRAMES
        for j, fc in enumerate(self.fcurves):
            co[:, 1] = values[:, j]
            fc.keyframe_points.foreach_set("co", co.ravel())
            fc.update()

    def remove(self) -> None:
        """Drop the animation: the object keeps whatever pose is set next."""
        action = self.object.animation_data.action if self.object.animation_data else None
        self.object.animation_data_clear()
        if action is not None and action.users == 0:
            bpy.data.actions.remove(action)


def yaw_values(xyz: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    """(k, 6) key values of yaw-only poses: positions ``xyz`` (k, 3) metres and headings ``yaw`` (k,) radians."""
    out = np.zeros((len(yaw), 6))
    out[:, :3] = xyz
    out[:, 5] = yaw
    return out


def blender_values(ob: bpy.types.Object, matrices) -> np.ndarray:
    """(3, 6) key values of three rigid poses (opening, instant, closing), decomposed by Blender itself.

    Each pose ((4, 4), world) is assigned to the ``matrix_world`` of a scratch object (outside
    every scene, so nothing is re-evaluated) that starts from ``ob``'s current rotation, and its
    location and Euler rotation are read back, the instant first: its key then holds exactly what
    a plain ``ob.matrix_world`` assignment of the same pose leaves on ``ob``, so a keyed render at
    :data:`FRAME` equals an unkeyed one bit for bit; the opening's and closing's Euler angles stay
    continuous with the instant's (Blender's compatible-Euler decomposition).
    """
    scratch = bpy.data.objects.get(SCRATCH) or bpy.data.objects.new(SCRATCH, None)
    scratch.rotation_mode = ob.rotation_mode
    scratch.rotation_euler = ob.rotation_euler
    out = np.empty((3, 6))
    for i in (1, 0, 2):
        scratch.matrix_world = matrices[i]
        out[i] = (*scratch.location, *scratch.rotation_euler)
    return out


def set_frame(scene: bpy.types.Scene) -> None:
    """Evaluate the scene at the image instant (after keys changed)."""
    scene.frame_set(FRAME)
