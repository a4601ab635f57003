"""Render one frame with a renderer and write its image files (EXR, metadata JSON, preview PNG).

Pure Python: the renderer is passed in (a :class:`generator.blender.renderer.Renderer`
in production), so this module never imports bpy. Every file is written atomically,
the metadata last, so a metadata file present means the image is complete.
"""

from __future__ import annotations

import time
from pathlib import Path

from generator.atomic import inside, write_json
from generator.imaging.exr import LabelledImage, write_exr
from generator.imaging.metadata import image_metadata, validate_metadata
from generator.imaging.preview import write_preview
from generator.rng import stream


def image_name(frame_index: int, time_of_day: str = "day", weather: str = "clear") -> str:
    """File stem of an image: ``NNNNNN_<time>_<weather>``."""
    return f"{frame_index:06d}_{time_of_day}_{weather}"


def draw_sun(spec, frame_index: int) -> tuple[float, float]:
    """Sun elevation and azimuth (degrees) of a day frame, from the spec ranges."""
    g = stream(spec.seed, "frame", frame_index, "sun")
    w = spec.weather
    return float(g.uniform(*w.sun_elevation_deg)), float(g.uniform(*w.sun_azimuth_deg))


def render_and_write(renderer, scene, spec, cfg, frame, out: Path) -> dict:
    """Render ``frame`` by day in clear weather and write ``out/images/<name>.{exr,json}`` (+ preview).

    Returns
    -------
    dict
        Seconds per stage (render passes, EXR write, metadata, preview).
    """
    from generator.blender.lighting import DayLight  # data class only; no bpy import at module level

    elevation, azimuth = draw_sun(spec, frame.index)
    light = renderer.set_day(DayLight(elevation, azimuth))
    light["time_of_day"] = "day"
    rendered = renderer.render(frame.T_world_camera, seed=frame.index, light_info=light)
    return write_image(out, frame, spec, cfg, renderer, rendered, "day", {"kind": "clear"})


def write_image(out: Path, frame, spec, cfg, renderer, rendered, time_of_day: str, weather: dict,
                rgb=None, name: str | None = None) -> dict:
    """Write one image variant (``rgb`` overrides the rendered RGB, e.g. after fog in post)."""
    secs = dict(rendered.seconds)
    name = name or image_name(frame.index, time_of_day, weather["kind"])
    folder = inside(out, "images")
    lab = rendered.labels
    rgb = rendered.rgb if rgb is None else rgb
    t = time.perf_counter()
    write_exr(folder / f"{name}.exr", LabelledImage(rgb, lab.class_id, lab.instance, lab.depth,
                                                     {"urbangen.image": name}), cfg.exr_codec)
    secs["exr_write"] = time.perf_counter() - t
    files = {"exr": f"{name}.exr"}
    if cfg.preview:
        t = time.perf_counter()
        write_preview(folder / f"{name}_preview.png", rgb, lab.class_id, lab.depth)
        secs["preview"] = time.perf_counter() - t
        files["preview"] = f"{name}_preview.png"
    t = time.perf_counter()
    record = image_metadata(image=name, files=files, frame=frame, k=renderer.k, width=cfg.width, height=cfg.height,
                            hfov_deg=spec.sensors.camera.hfov_deg, class_id=lab.class_id, time_of_day=time_of_day,
                            weather=weather, lighting=rendered.lighting, spec=spec, render_cfg=cfg,
                            device=renderer.device, timings=secs, blender_version=renderer.blender_version)
    problems = validate_metadata(record)
    if problems:
        raise RuntimeError(f"metadata of {name} does not match its schema: {problems[0]}")
    write_json(folder / f"{name}.json", record)
    secs["metadata"] = time.perf_counter() - t
    return secs
