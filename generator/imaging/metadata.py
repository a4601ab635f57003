"""Per-image metadata JSON (seed 003 Sec. III.D, and what a user needs to trust the labels).

Built from pure data (frame, rig, render config, label counts); validated against
``generator/spec/schemas/metadata.schema.json`` before it is written.
"""

from __future__ import annotations

import math
import platform
from importlib import metadata as importlib_metadata

import numpy as np

from generator import __version__
from generator.imaging.exr import DEPTH_DEFINITION
from generator.imaging.meta_fields import schema_message
from generator.labels import class_table
from generator.spec.towns import angle_record, town_record
from generator.spec.validate import load_schema

METADATA_VERSION = 1


def _list(m: np.ndarray) -> list:
    return np.asarray(m, np.float64).round(9).tolist()


def camera_angles(T_world_camera: np.ndarray) -> dict:
    """Yaw, pitch and tilt (roll) in degrees of an optical camera pose.

    yaw: heading of the optical axis, counter-clockwise from world +x; pitch: elevation of
    the optical axis above the horizon; tilt: rotation about the optical axis, positive
    when the image's right side goes down (camera rolls clockwise as seen from behind).
    """
    r = T_world_camera[:3, :3]
    fwd, right = r[:, 2], r[:, 0]
    yaw = math.degrees(math.atan2(fwd[1], fwd[0]))
    pitch = math.degrees(math.asin(max(-1.0, min(1.0, fwd[2]))))
    level_right = np.cross(fwd, [0.0, 0.0, 1.0])
    n = np.linalg.norm(level_right)
    tilt = 0.0 if n < 1e-9 else math.degrees(math.atan2(-right[2], float(np.dot(right, level_right / n))))
    return {"yaw": yaw, "pitch": pitch, "tilt": tilt}


def software_versions(blender: str | None = None) -> dict:
    """Versions of the software that produced a file."""
    out = {"urbangen": __version__, "python": platform.python_version()}
    for dist in ("numpy", "OpenEXR", "embreex", "trimesh"):
        try:
            out[dist] = importlib_metadata.version(dist)
        except importlib_metadata.PackageNotFoundError:
            pass
    if blender:
        out["blender"] = blender
    return out


def class_pixels(class_id: np.ndarray) -> dict[str, int]:
    """Pixel count per class present (non-zero counts only), in class-table order."""
    counts = np.bincount(class_id.ravel(), minlength=len(class_table()))
    return {name: int(c) for name, c in zip(class_table().names, counts, strict=False) if c > 0}


def image_metadata(*, image: str, files: dict, frame, k: np.ndarray, width: int, height: int, hfov_deg: float,
                   class_id: np.ndarray, time_of_day: str, weather: dict, lighting: dict, spec, render_cfg,
                   device: str, timings: dict, blender_version: str | None, camera_model: dict | None = None,
                   motion: dict | None = None) -> dict:
    """The metadata record of one image.

    Parameters
    ----------
    frame : generator.world.rig.Frame
    k : (3, 3) float64
        Intrinsics.
    class_id : (H, W) uint8
        The label map (masks) of the image.
    camera_model : dict, optional
        The camera model's record (:func:`generator.postfx.camera.apply_camera`); None when
        the model is off, and then the record has no ``camera_model`` section (as before it).
    motion : dict, optional
        The ``motion`` section (:func:`generator.jobs.exposure.motion_record`): the motion-blur
        settings and every visible actor's velocity at the image time ``frame.t`` (written as
        ``time_s``); None leaves it out.
    """
    T = frame.T_world_camera
    jit = frame.camera_jitter
    record = {
        "metadata_version": METADATA_VERSION,
        "image": image,
        "files": files,
        "frame": frame.index,
        "scene": spec.name,
        "seed": spec.seed,
        "spec_hash": spec.spec_hash,
        **({"town": town_record(spec)} if getattr(spec, "town_index", None) is not None else {}),
        **angle_record(spec),
        "camera": {
            "position_m": _list(T[:3, 3]),
            "rotation_deg": {key: v for key, v in camera_angles(T).items() if key != "tilt"},
            "tilt_deg": camera_angles(T)["tilt"],
            # the same signs as rotation_deg / tilt_deg: yaw left, pitch up, roll = tilt (right side down)
            "jitter_deg": {"yaw": math.degrees(jit[0]), "pitch": -math.degrees(jit[1]), "roll": math.degrees(jit[2])},
            "T_world_camera": _list(T),
            "T_ego_camera": _list(frame.T_ego_camera),
            "frame_convention": "optical: x right, y down, z forward; T maps camera to world",
            "intrinsics": {"width": width, "height": height, "hfov_deg": hfov_deg, "fx": float(k[0, 0]),
                           "fy": float(k[1, 1]), "cx": float(k[0, 2]), "cy": float(k[1, 2]), "K": _list(k)},
        },
        "time_s": float(frame.t),
        "ego": {"T_world_ego": _list(frame.T_world_ego), "s_m": frame.s, "t_s": frame.t},
        "time_of_day": time_of_day,
        "weather": weather,
        "lighting": lighting,
        "classes_present": class_pixels(class_id),
        "depth": DEPTH_DEFINITION,
        "render": {**render_cfg.to_dict(), "config_hash": render_cfg.config_hash, "device": device},
        "timings_s": {key: round(float(v), 4) for key, v in timings.items()},
        "software": software_versions(blender_version),
    }
    if camera_model is not None:
        record["camera_model"] = camera_model
    if motion is not None:
        record["motion"] = motion
    return record


def validate_metadata(record: dict) -> list[str]:
    """Problems of a metadata record against its schema (empty when valid); one line each, naming
    the field and never the value (:func:`schema_message`)."""
    import jsonschema

    v = jsonschema.Draft202012Validator(load_schema("metadata"))
    return [schema_message(e) for e in v.iter_errors(record)]
