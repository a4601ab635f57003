"""The Blender camera from the rig: optical-frame pose and pinhole intrinsics."""

from __future__ import annotations

import math

import numpy as np

from generator.blender.bpy_guard import bpy, mathutils

#: Blender cameras look along local -z with +y up; the optical frame looks along +z with +y down.
R_OPTICAL_BLENDER = np.diag([1.0, -1.0, -1.0])


def place(scene: "bpy.types.Scene", T_world_camera: np.ndarray, hfov_deg: float) -> "bpy.types.Object":
    """Create (once) and place the scene camera.

    Parameters
    ----------
    T_world_camera : (4, 4) float64
        Pose of the optical camera frame (x right, y down, z forward) in the world.
    hfov_deg : float
        Horizontal field of view; the principal point stays at the image centre.
    """
    cam = bpy.data.objects.get("urbangen_camera")
    if cam is None:
        cam = bpy.data.objects.new("urbangen_camera", bpy.data.cameras.new("urbangen_camera"))
        scene.collection.objects.link(cam)
    m = T_world_camera.copy()
    m[:3, :3] = m[:3, :3] @ R_OPTICAL_BLENDER
    cam.matrix_world = mathutils.Matrix(m.tolist())
    data = cam.data
    data.type = "PERSP"
    data.sensor_fit = "HORIZONTAL"
    data.angle_x = math.radians(hfov_deg)
    data.shift_x = data.shift_y = 0.0
    data.clip_start = 0.05
    data.clip_end = 10000.0  # beyond the 2 km ground ring: no gap at the horizon
    scene.camera = cam
    return cam
