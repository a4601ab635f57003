"""All weather x time-of-day variants of one frame, at the cost of a few renders.

Per frame: the label passes once (masks, instances and depth are shared by every
variant); one RGB render per (time of day, dry | wet, clear sky | overcast)
(:func:`generator.weather.render_key`: clear is sunny and dry, fog overcast and dry, the
wet kinds overcast and wet); then fog and rain in post-processing from the depth pass (seed
003 Sec. III.A), then the camera model when the render config turns it on
(:func:`camera_post`: the camera sees the foggy, rainy scene). The 12 combinations of Table
II therefore cost 6 RGB renders, and a frame's variants differ only in RGB.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from generator.jobs.exposure import expose, motion_record
from generator.jobs.images import write_image
from generator.postfx.camera import apply_camera, draw_params
from generator.postfx.fog import fog_image
from generator.postfx.rain import rain_image
from generator.rng import child_seed, stream
from generator.weather import (
    DEFAULT_TIMES,
    TIMES,
    combinations,
    draw_lighting,
    draw_weather,
    frame_wetness,
    has_fog,
    has_rain,
    light_level,
    render_key,
)

#: Memory a worker may hold in finished label arrays of a batch (see :func:`label_batch_size`).
LABEL_BATCH_BYTES = 256 * 2**20
#: Most frames in one label batch: a worker's first RGB image waits for its batch's labels.
LABEL_BATCH_MAX = 16


def parse_combos(text: str, times=DEFAULT_TIMES) -> list[tuple[str, str]]:
    """``all`` | ``clear`` | ``day:clear,dusk:fog,night:rain_fog,...`` -> list of (time_of_day, kind).

    ``all`` is every weather at each of ``times`` (the spec's ``weather.times_of_day``); pairs
    may name any time of day urbangen knows (:data:`generator.weather.TIMES`).

    Raises
    ------
    ValueError
        With a message naming the bad item.
    """
    if text == "all":
        return combinations(times)
    if text == "clear":
        return [("day", "clear")]
    out = []
    valid = set(combinations(TIMES))
    for item in text.split(","):
        pair = tuple(item.strip().split(":"))
        if pair not in valid:
            raise ValueError(f"unknown variant {item!r}; use all, clear or time:weather pairs like day:fog "
                             f"(times: {', '.join(TIMES)}; weather: clear, fog, rain, rain_fog, wet, wet_fog)")
        out.append(pair)
    return list(dict.fromkeys(out))


def renders_needed(combos: list[tuple[str, str]]) -> list[tuple[str, bool, bool]]:
    """The (time_of_day, wet, overcast) renders that serve ``combos``, in a fixed order."""
    return sorted({(t, *render_key(k)) for t, k in combos}, key=lambda r: (TIMES.index(r[0]), r[1], r[2]))


def cycles_seed(spec, frame_index: int, time_of_day: str, wet: bool, overcast: bool) -> int:
    """Cycles' seed of one RGB render (the sunny renders keep the seeds they had before skies were drawn)."""
    return child_seed(
        spec.seed, "frame", frame_index, "cycles", time_of_day, int(wet), *(("overcast",) if overcast else ())
    )


def weather_post(spec, frame_index: int, time_of_day: str, kind: str, rgb: np.ndarray, depth: np.ndarray,
                 k: np.ndarray, stream_tag: tuple = (), level: float = 1.0) -> tuple[np.ndarray, dict]:
    """Fog and rain of weather ``kind`` applied in post to one rendered image.

    The post fx are written for a clear day's radiance (their airlight, emitter thresholds and
    streak clips are radiances): they run on ``rgb / level`` and the result is scaled back, so a
    dim dusk or night render gets fog and rain in proportion to its own light.

    Parameters
    ----------
    rgb : (H, W, 3) float32
        The rendered linear RGB (dry or wet render, as ``kind`` needs).
    depth : (H, W) float32
        Depth pass, metres along the ray (inf = sky).
    k : (3, 3) float64
        Camera intrinsics (rain streak lengths).
    stream_tag : tuple
        Extra names of the rain stream (another camera of the same frame draws its own drops).
    level : float
        The scene's light relative to a clear day (:func:`generator.weather.light_level`).

    Returns
    -------
    ((H, W, 3) float32, dict)
        The image and the weather record of its metadata.
    """
    weather = draw_weather(spec, frame_index, kind)
    img, params = rgb, weather.to_dict()
    if not (has_fog(kind) or has_rain(kind)):
        return img, params
    scale = np.float32(level)
    img = img / scale
    if has_fog(kind):
        img, params["fog"] = fog_image(img, depth, weather.visibility_m, time_of_day)
    if has_rain(kind):
        g = stream(spec.seed, "frame", frame_index, "rain", time_of_day, kind, *stream_tag)
        img, params["rain"] = rain_image(img, depth, weather.rain_rate_mmh, g, time_of_day, k=k)
    params["post_fx_light_level"] = float(level)
    return (img * scale).astype(np.float32, copy=False), params


def camera_post(spec, cfg, frame_index: int, time_of_day: str, kind: str, rgb: np.ndarray,
                stream_tag: tuple = (), noise_tag: tuple = (),
                exposure: dict | None = None) -> tuple[np.ndarray, dict | None]:
    """The camera model (:mod:`generator.postfx.camera`) on one image after its fog and rain.

    Off (``cfg.camera_model`` false) it returns ``rgb`` itself and None: the image is written
    exactly as before the model existed.

    Parameters
    ----------
    rgb : (H, W, 3) float32
        Linear radiance after :func:`weather_post`.
    stream_tag : tuple
        Extra names of the camera's stream (``("stereo",)``: both cameras of a pair share one camera).
    noise_tag : tuple
        Extra names of a separate noise stream (each camera of a pair has its own sensor noise).
    exposure : dict, optional
        Use this exposure (a record's ``exposure``) instead of metering: a stereo pair is exposed
        as its left camera meters.

    Returns
    -------
    ((H, W, 3) float32, dict or None)
        The EXR RGB and the ``camera_model`` section of the image's metadata (None when off).
    """
    if not cfg.camera_model:
        return rgb, None
    g = stream(spec.seed, "frame", frame_index, "camera_model", time_of_day, kind, *stream_tag)
    params = draw_params(g, time_of_day)
    if noise_tag:
        g = stream(spec.seed, "frame", frame_index, "camera_model", time_of_day, kind, *stream_tag, *noise_tag, "noise")
    return apply_camera(rgb, params, g, exposure)


def pose_for(renderer, frame, rig=None) -> Callable[[], None]:
    """A callable that poses ``renderer`` for ``frame``: exposed at ``frame.t`` on the drive's
    timeline with ``rig`` (:func:`generator.jobs.exposure.expose`), else the camera at
    ``frame.T_world_camera`` as is."""
    if rig is None:
        return lambda: renderer.place_camera(frame.T_world_camera)
    return lambda: expose(renderer, rig, frame.t, frame.T_ego_camera)


def label_batch_size(cfg) -> int:
    """How many frames' label passes a worker renders behind one switch of the render state: as
    many as fit :data:`LABEL_BATCH_BYTES` of finished label arrays, 1..:data:`LABEL_BATCH_MAX`."""
    per_frame = cfg.width * cfg.height * (1 + 2 + 1 + 2 + 4)   # class, instance, real class, real instance, depth
    return int(max(1, min(LABEL_BATCH_MAX, LABEL_BATCH_BYTES // per_frame)))


def render_frames(renderer, spec, cfg, frames, out: Path, combos: list[tuple[str, str]], rig=None):
    """Render and write every variant of each of ``frames``, the label passes of
    :func:`label_batch_size` frames at a time (Cycles recompiles every shader when it switches
    between the RGB and the label state, so switching once per batch instead of twice per frame
    saves most of the labels' cost; the images are the same either way).

    Yields
    ------
    (frame, dict)
        Each frame, in order, with what :func:`render_frame` returns for it.
    """
    frames = list(frames)
    n = label_batch_size(cfg)
    for i in range(0, len(frames), n):
        batch = frames[i:i + n]
        labels = renderer.render_labels_batch([pose_for(renderer, f, rig) for f in batch])
        for frame, lab in zip(batch, labels, strict=False):
            yield frame, render_frame(renderer, spec, cfg, frame, out, combos, rig, lab)


def render_frame(renderer, spec, cfg, frame, out: Path, combos: list[tuple[str, str]], rig=None,
                 labels=None) -> dict[str, dict]:
    """Render and write every variant in ``combos`` of ``frame``.

    With ``rig`` (a :class:`generator.world.rig.Rig`), the image is exposed at ``frame.t`` on the
    drive's timeline (:func:`generator.jobs.exposure.expose`: the world's actors where their tracks
    are then, the camera moving over the shutter when motion blur is on) and its metadata gets the
    ``motion`` record; without, the camera is put at ``frame.T_world_camera`` as is. ``labels``
    (:class:`generator.blender.passes.LabelPasses`) are this frame's label passes if already
    rendered (:func:`render_frames`); None renders them here.

    Returns
    -------
    dict
        Image name -> seconds per stage.
    """
    pose_for(renderer, frame, rig)()
    if labels is None:
        labels = renderer.render_labels()
    label_s = sum(labels.seconds.values())
    motion = None if rig is None else motion_record(renderer, frame.t, labels.instance, frame.T_world_camera,
                                                    frame.T_ego_camera)
    timings = {}
    for tod, wet, overcast in renders_needed(combos):
        kinds = [k for t_, k in combos if t_ == tod and render_key(k) == (wet, overcast)]
        light = draw_lighting(spec, frame.index, tod, kinds[0])
        level = light_level(light)
        wetness, puddles = frame_wetness(spec, frame.index) if wet else (0.0, 0.0)
        info = renderer.set_conditions(light, wetness, puddles)
        info.update({k: v for k, v in light.to_dict().items() if v is not None}, light_level=level)
        rgb, rgb_s = renderer.render_rgb(seed=cycles_seed(spec, frame.index, tod, wet, overcast))
        for kind in kinds:
            t = time.perf_counter()
            img, params = weather_post(spec, frame.index, tod, kind, rgb, labels.depth, renderer.k, level=level)
            post_s = time.perf_counter() - t
            secs = {"rgb_pass": rgb_s, "label_passes_shared": label_s, "post_fx": post_s}
            t = time.perf_counter()
            img, camera = camera_post(spec, cfg, frame.index, tod, kind, img)
            if camera is not None:
                secs["camera_model"] = time.perf_counter() - t
            rendered = _Rendered(labels, info, secs)
            name, written = write_image(out, frame, spec, cfg, renderer, rendered, tod, params, rgb=img, camera=camera,
                                        motion=motion)
            timings[name] = written
    return timings


class _Rendered:
    """The shared passes of a frame in the shape :func:`write_image` reads."""

    def __init__(self, labels, lighting: dict, seconds: dict):
        self.labels, self.lighting, self.seconds, self.rgb = labels, lighting, seconds, None
