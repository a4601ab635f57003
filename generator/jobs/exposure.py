"""An image's exposure on the drive's timeline: the renderer's world and camera at time ``t``, and
what the image's metadata says about motion.

An image is exposed at ``t`` (seconds on the drive's timeline): the actors stand where their
tracks are at ``t`` and the camera where the rig puts it, ``rig.T_world_ego(t) @ T_ego_camera``.
With motion blur on (render config ``motion_blur``) the RGB pass integrates both over the exposure
``[t - shutter/2, t + shutter/2]``; the label passes stay at ``t``. Pure Python: the renderer is
passed in.
"""

from __future__ import annotations

import numpy as np

from generator.world.actors import MOVING_THRESHOLD_MPS
from generator.world.kinematics import camera_motion, ego_motion


def expose(renderer, rig, t: float, T_ego_camera: np.ndarray) -> np.ndarray:
    """Pose ``renderer``'s actors and camera for an image at time ``t``.

    Parameters
    ----------
    renderer : generator.blender.renderer.Renderer
    rig : generator.world.rig.Rig
        With the drive's trajectory.
    t : float
        Image time, seconds.
    T_ego_camera : (4, 4) float64
        Camera (optical frame) mount in the ego frame, jitter included.

    Returns
    -------
    (4, 4) float64
        ``T_world_camera`` at ``t`` (the pose the label passes and the metadata hold).
    """
    renderer.set_time(t)
    T_world_camera = rig.T_world_ego(t)[0] @ T_ego_camera
    shutter = None
    if renderer.cfg.motion_blur.enabled:
        times = renderer.shutter_times(t)
        shutter = rig.T_world_ego(times[[0, 2]]) @ T_ego_camera
    renderer.place_camera(T_world_camera, shutter)
    return T_world_camera


def visible_actors(world, t: float, instance: np.ndarray, T_world_camera: np.ndarray | None = None) -> list[dict]:
    """Every actor with pixels in an image's instance pass, with its motion at ``t``.

    Parameters
    ----------
    world : generator.world.actors.World or None
    t : float
        Image time, seconds.
    instance : (H, W) uint16
        The image's instance ids (label pass, the masks').
    T_world_camera : (4, 4) float64, optional
        The camera's pose (optical frame): adds ``velocity_camera_mps``.

    Returns
    -------
    list of dict
        In ``world.actors`` order: ``uid``, ``name``, ``kind``, ``class``, ``instance_id``,
        ``pixels``, ``velocity_mps`` (world frame, the track's central difference at ``t``),
        ``speed_mps`` (horizontal), ``moving`` (faster than the moving-* threshold) and, with
        the camera pose, ``velocity_camera_mps`` (the same velocity in the camera's optical axes).
    """
    if world is None or not world.actors:
        return []
    counts = np.bincount(instance.ravel(), minlength=1 + max(a.instance_id for a in world.actors))
    out = []
    for a in world.actors:
        pixels = int(counts[a.instance_id])
        if pixels == 0:
            continue
        v = a.track.velocity(t)[0]
        speed = float(a.track.speed(t)[0])
        rec = {"uid": a.uid, "name": a.name, "kind": a.kind, "class": a.cls, "instance_id": a.instance_id,
               "pixels": pixels, "velocity_mps": [float(x) for x in v], "speed_mps": speed,
               "moving": speed > MOVING_THRESHOLD_MPS}
        if T_world_camera is not None:
            rec["velocity_camera_mps"] = [float(x) for x in np.asarray(T_world_camera)[:3, :3].T @ v]
        out.append(rec)
    return out


def motion_record(renderer, t: float, instance: np.ndarray, T_world_camera: np.ndarray | None = None,
                  T_ego_camera: np.ndarray | None = None) -> dict:
    """The ``motion`` section of an image's metadata: the motion-blur settings the RGB was rendered
    with, the visible actors (:func:`visible_actors`) at the image time ``t`` and, given the camera's
    mount ``T_ego_camera``, the ego's motion and the camera's twist then (``ego``,
    :func:`generator.world.kinematics.ego_motion` and :func:`~generator.world.kinematics.camera_motion`):
    the ego part and the object part of the image's optical flow."""
    world = renderer.world
    record = {"motion_blur": renderer.motion_blur, "actors": visible_actors(world, t, instance, T_world_camera)}
    if world is not None and T_ego_camera is not None:
        record["ego"] = {**ego_motion(world.ego, t), "camera": camera_motion(world.ego, T_ego_camera, t)}
    return record
