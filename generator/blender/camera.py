"""The Blender camera from the rig: optical-frame pose (optionally moving during the exposure) and
pinhole intrinsics."""

from __future__ import annotations

import math

import numpy as np

from generator.blender import motion
from generator.blender.bpy_guard import bpy, mathutils

#: Blender cameras look along local -z with +y up; the optical frame looks along +z with +y down.
R_OPTICAL_BLENDER = np.diag([1.0, -1.0, -1.0])


def _blender(T_world_camera: np.ndarray) -> mathutils.Matrix:
    m = np.array(T_world_camera, np.float64)
    m[:3, :3] = m[:3, :3] @ R_OPTICAL_BLENDER
    return mathutils.Matrix(m.tolist())


def place(scene: bpy.types.Scene, T_world_camera: np.ndarray, hfov_deg: float,
          shutter: np.ndarray | None = None) -> bpy.types.Object:
    """Create (once) and place the scene camera.

    Parameters
    ----------
    T_world_camera : (4, 4) float64
        Pose of the optical camera frame (x right, y down, z forward) in the world at the image instant.
    hfov_deg : float
        Horizontal field of view; the principal point stays at the image centre.
    shutter : (2, 4, 4) float64, optional
        Optical-frame poses when the shutter opens and closes: the camera is keyed
        (:mod:`generator.blender.motion`) so Cycles' motion blur sees it move. None: a still
        camera (no animation), exactly as before motion blur existed.
    """
    cam = bpy.data.objects.get("urbangen_camera")
    if cam is None:
        cam = bpy.data.objects.new("urbangen_camera", bpy.data.cameras.new("urbangen_camera"))
        scene.collection.objects.link(cam)
    if shutter is None:
        if motion.Keys.present(cam):
            motion.Keys(cam).remove()
        cam.matrix_world = _blender(T_world_camera)
    else:
        motion.Keys(cam).set(
            motion.blender_values(cam, [_blender(shutter[0]), _blender(T_world_camera), _blender(shutter[1])])
        )
        motion.set_frame(scene)
    data = cam.data
    data.type = "PERSP"
    data.sensor_fit = "HORIZONTAL"
    data.angle_x = math.radians(hfov_deg)
    data.shift_x = data.shift_y = 0.0
    data.clip_start = 0.05
    data.clip_end = 10000.0  # beyond the 2 km ground ring: no gap at the horizon
    if scene.camera != cam:  # assigning it again would rebuild the scene's dependency graph
        scene.camera = cam
    return cam
