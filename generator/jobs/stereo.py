"""The KITTI camera stream of a LiDAR sequence: a fixed stereo pair beside the scans.

Every ``sensors.stereo.every``-th 10 Hz sweep ``k`` of ``sequences/NN`` (default every 10th: one
pair a second) gets a rectified stereo
pair (:meth:`generator.world.rig.Rig.T_ego_stereo`: camera 2 at the nominal camera mount,
camera 3 ``baseline_m`` to its right, no jitter), so ``P2 @ Tr`` of the sequence's
``calib.txt`` projects the scan into its image exactly as KITTI tools do:

============================== ===========================================================
``image_2/NNNNNN.png``         left image, 8-bit sRGB (``image_3/`` the right one)
``semantic_2/NNNNNN.png``      Cityscapes label id per pixel, uint8 (KITTI semantics layout)
``passes_2/NNNNNN.exr``        the dataset EXR: linear RGB, one mask per native class,
                               depth (metres along the ray) and instance ids
``passes_2/NNNNNN.json``       exposure time, camera pose (world), intrinsics, weather, motion
                               (blur settings, visible actors' velocities) and the camera
                               model's record when it is on
============================== ===========================================================

Camera model (render config ``camera_model: true``): both cameras of the pair are one camera
model (one draw from ``("frame", k, "camera_model", time, weather, "stereo")``), exposed as the
left camera meters (a synchronised rig), each with its own sensor noise; ``image_2|3`` are the
response curve of their EXR RGB. Off: the fixed tone mapping, as before.

Exposure: KITTI triggers its cameras when the spinning LiDAR faces forward; here the pair
is exposed at the sweep start plus the firing time of the column looking along +x
(:func:`exposure_offset`, 0 with motion skew off), so the points in the camera's view are
fired within a few milliseconds of the exposure. Weather and time of day are the scan's
own (:func:`generator.weather.lidar_combination`): the images show what the scan saw.
"""

from __future__ import annotations

import functools
import time
from pathlib import Path

import numpy as np
from PIL import Image

from generator.atomic import atomic_path, write_json
from generator.imaging.exr import LabelledImage, write_exr
from generator.jobs.exposure import expose, motion_record
from generator.jobs.variants import camera_post, weather_post
from generator.labels import class_table
from generator.previews.preview import display_rgb
from generator.rng import child_seed
from generator.weather import draw_lighting, frame_wetness, is_wet, lidar_combination, light_level

CAMERAS = (2, 3)


def exposure_offset(sensor, motion_skew: bool) -> float:
    """Seconds after the sweep start when the LiDAR fires the column looking forward (+x)."""
    if not motion_skew:
        return 0.0
    az = np.angle(np.exp(1j * sensor.column_azimuth()))
    return float(sensor.column_time()[int(np.argmin(np.abs(az)))])


def stereo_frames(spec, frames) -> list[int]:
    """The scans of ``frames`` that get a stereo pair (every ``sensors.stereo.every``-th; none if disabled)."""
    st = spec.sensors.stereo
    return [k for k in frames if st.enabled and k % st.every == 0]


def files_of(seq_dir: Path, index: int) -> list[Path]:
    """Every file of scan ``index``'s pair, in the order they are written (the last one marks it done)."""
    stem = f"{index:06d}"
    out = []
    for cam in CAMERAS:
        out += [seq_dir / f"passes_{cam}" / f"{stem}.exr", seq_dir / f"passes_{cam}" / f"{stem}.json",
                seq_dir / f"semantic_{cam}" / f"{stem}.png"]
    return out + [seq_dir / "image_2" / f"{stem}.png", seq_dir / "image_3" / f"{stem}.png"]


def pair_done(seq_dir: Path, index: int) -> bool:
    return all(p.is_file() for p in files_of(seq_dir, index))


def _png(path: Path, array: np.ndarray) -> None:
    with atomic_path(path, suffix=".png") as tmp:
        Image.fromarray(array).save(tmp, format="PNG", optimize=False)


def render_pair(renderer, spec, cfg, rig, sensor, index: int, seq_dir: Path) -> dict[str, float]:
    """Render and write the stereo pair of scan ``index`` into ``seq_dir``.

    Parameters
    ----------
    renderer : generator.blender.renderer.Renderer
    rig : generator.world.rig.Rig
        With the trajectory of the sequence's route.
    sensor : generator.lidar.sensors.Sensor
        The sequence's LiDAR (for the forward-firing instant).

    Returns
    -------
    dict
        Seconds per stage.
    """
    t0 = time.perf_counter()
    tod, kind = lidar_combination(index, spec.weather.times_of_day)
    t_scan = rig.sweep_time(index)  # the start of sweep ``index`` (10 Hz)
    t_exp = t_scan + exposure_offset(sensor, spec.sensors.lidar.motion_skew)
    light = draw_lighting(spec, index, tod, kind)
    wetness, puddles = frame_wetness(spec, index) if is_wet(kind) else (0.0, 0.0)
    lighting = renderer.set_conditions(light, wetness, puddles)
    to_cs = class_table().to_cityscapes
    stem = f"{index:06d}"
    images, exposure = {}, None
    # both cameras' label passes behind one switch of the render state (see render_label_batch)
    poses = [functools.partial(expose, renderer, rig, t_exp, rig.T_ego_stereo(cam)) for cam in CAMERAS]
    pair_labels = renderer.render_labels_batch(poses)
    for cam, pose, labels in zip(CAMERAS, poses, pair_labels, strict=False):
        T_world_camera = pose()
        rgb, _ = renderer.render_rgb(seed=child_seed(spec.seed, "frame", index, "stereo", cam))
        img, weather = weather_post(spec, index, tod, kind, rgb, labels.depth, renderer.k, ("stereo", cam),
                                    light_level(light))
        img, camera = camera_post(spec, cfg, index, tod, kind, img, ("stereo",), (cam,), exposure)
        if camera is not None:
            camera["exposure_from"] = f"image_{CAMERAS[0]}"
            exposure = camera["exposure"]
        write_exr(seq_dir / f"passes_{cam}" / f"{stem}.exr",
                  LabelledImage(img, labels.class_id, labels.instance, labels.depth,
                                {"urbangen.image": f"image_{cam}/{stem}"}), cfg.exr_codec)
        record = {
            "image": f"image_{cam}/{stem}.png", "camera": cam, "scan": index, "time_s": t_exp,
            "exposure_offset_s": t_exp - t_scan, "T_world_camera": T_world_camera.tolist(),
            "K": renderer.k.tolist(), "width": cfg.width, "height": cfg.height, "time_of_day": tod,
            "weather": weather, "lighting": {k: v for k, v in lighting.items() if k != "light_objects"},
            "seed": spec.seed, "spec_hash": spec.spec_hash,
            "motion": motion_record(renderer, t_exp, labels.instance, T_world_camera, rig.T_ego_stereo(cam))}
        if camera is not None:
            record["camera_model"] = camera
        write_json(seq_dir / f"passes_{cam}" / f"{stem}.json", record)
        _png(seq_dir / f"semantic_{cam}" / f"{stem}.png", to_cs[labels.class_id])
        images[cam] = display_rgb(img, camera)
    for cam in CAMERAS:  # the images last: image_3 present means the pair is complete
        _png(seq_dir / f"image_{cam}" / f"{stem}.png", images[cam])
    return {"stereo_s": time.perf_counter() - t0}
