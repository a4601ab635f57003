"""Write one image's files (EXR, metadata JSON, preview PNG).

Pure Python: the renderer is passed in (a :class:`generator.blender.renderer.Renderer`
in production) only for its intrinsics, device and version, so this module never
imports bpy. Every file is written atomically, the metadata last, so a metadata file
present means the image is complete. Files go to the frame's shard folder,
``images/SSSS/`` (:mod:`generator.imaging.paths`).
"""

from __future__ import annotations

import time
from pathlib import Path

from generator.atomic import inside, write_json
from generator.imaging.exr import LabelledImage, write_exr
from generator.imaging.metadata import image_metadata, validate_metadata
from generator.imaging.paths import IMAGES_DIR, image_name, shard_name
from generator.previews.preview import write_preview


def write_image(out: Path, frame, spec, cfg, renderer, rendered, time_of_day: str, weather: dict,
                rgb=None, name: str | None = None, camera: dict | None = None,
                motion: dict | None = None) -> tuple[str, dict]:
    """Write one image variant (``rgb`` overrides the rendered RGB, e.g. after fog in post).

    ``camera`` is the camera model's record (:func:`generator.jobs.variants.camera_post`):
    it goes into the metadata, and the preview shows the camera's 8-bit output; None (the
    model off) writes the files as before the model existed. ``motion`` is the image's motion
    record (:func:`generator.jobs.exposure.motion_record`: motion-blur settings, visible actors and
    their velocities at ``frame.t``).

    Returns
    -------
    (str, dict)
        The image name and the seconds per stage.
    """
    secs = dict(rendered.seconds)
    name = name or image_name(frame.index, time_of_day, weather["kind"])
    folder = inside(out, IMAGES_DIR, shard_name(frame.index))  # images/SSSS/ (generator.imaging.paths)
    lab = rendered.labels
    rgb = rendered.rgb if rgb is None else rgb
    files = {"exr": f"{name}.exr", **({"preview": f"{name}_preview.png"} if cfg.preview else {})}
    # The metadata is built and checked first: a record that does not match its schema
    # (a bug) stops here, before the EXR or the preview exist.
    planned = {**secs, "exr_write": 0.0, **({"preview": 0.0} if cfg.preview else {})}
    record = image_metadata(image=name, files=files, frame=frame, k=renderer.k, width=cfg.width, height=cfg.height,
                            hfov_deg=spec.sensors.camera.hfov_deg, class_id=lab.class_id, time_of_day=time_of_day,
                            weather=weather, lighting=rendered.lighting, spec=spec, render_cfg=cfg,
                            device=renderer.device, timings=planned, blender_version=renderer.blender_version,
                            camera_model=camera, motion=motion)
    problems = validate_metadata(record)
    if problems:
        raise RuntimeError(f"metadata of {name} does not match its schema: {problems[0]}")
    t = time.perf_counter()
    write_exr(folder / f"{name}.exr", LabelledImage(rgb, lab.class_id, lab.instance, lab.depth,
                                                     {"urbangen.image": name}), cfg.exr_codec)
    secs["exr_write"] = time.perf_counter() - t
    if cfg.preview:
        t = time.perf_counter()
        write_preview(folder / f"{name}_preview.png", rgb, lab.class_id, lab.depth, camera_model=camera)
        secs["preview"] = time.perf_counter() - t
    t = time.perf_counter()
    record["timings_s"] = {key: round(float(v), 4) for key, v in secs.items()}
    write_json(folder / f"{name}.json", record)  # last: an image with metadata is complete
    secs["metadata"] = time.perf_counter() - t
    return name, secs
