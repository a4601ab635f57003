"""Render passes as numpy arrays.

* RGB pass: the config's Cycles settings, label proxies hidden -> linear RGB.
* Label passes: the label material (:mod:`generator.blender.label_shader`) with the label
  proxies shown. Each sample yields exact integer ids: the mask class and instance (the first
  proxy or surface hit) and, for rays through pixel centres, which cross the proxies, the real
  surface behind them with its planar depth.
* Real pass: a 1x render -> class and instance of the real surface at each pixel centre and
  its depth (and the mask labels when ``label_supersample`` is 1).
* Label pass with a supersampling factor ``k`` (the config's ``label_supersample``, odd): the
  same scene rendered first at ``k`` times the resolution; each pixel takes the majority class
  of its ``k x k`` samples (:func:`generator.labels.supersample.majority_labels`): thin
  markings stop flickering as the camera moves, and every pixel still holds one exact class
  id. Depth is never voted or blended: it comes from the 1x render.

Depth is converted from Cycles' planar Z to the distance along the pixel's ray
(range, metres) so it compares directly with LiDAR range; sky pixels get +inf.
Background mode has no pixels in "Render Result", so each render is saved with
``save_render`` to an uncompressed float EXR in a scratch folder and read back.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import OpenEXR

from generator.world import rig
from generator.blender import geometry, label_shader, session
from generator.blender.bpy_guard import bpy
from generator.blender.materials import label_world
from generator.labels import label_colour
from generator.labels.supersample import majority_labels

SKY_Z = 1e9

log = logging.getLogger(__name__)


@dataclass
class LabelPasses:
    """Per-pixel labels of one camera pose.

    Attributes
    ----------
    class_id : (H, W) uint8
        Native class with label proxies (what the masks hold).
    instance : (H, W) uint16
        Instance id with label proxies (0 for stuff and sky).
    real_class : (H, W) uint8
        Native class of the real geometry (proxies hidden): what a ray from the camera hits.
    real_instance : (H, W) uint16
    depth : (H, W) float32
        Distance along the pixel's ray to the real geometry, metres; +inf for sky.
    seconds : dict
    """

    class_id: np.ndarray
    instance: np.ndarray
    real_class: np.ndarray
    real_instance: np.ndarray
    depth: np.ndarray
    seconds: dict = field(default_factory=dict)


#: Seconds spent inside Cycles' render call, accumulated per process (sampling, sync, denoise).
CYCLES_SECONDS = {"rgb": 0.0, "labels": 0.0}


def _render(scene, path: Path, kind: str = "labels") -> dict[str, np.ndarray]:
    t = time.perf_counter()
    bpy.ops.render.render(write_still=False)
    CYCLES_SECONDS[kind] += time.perf_counter() - t
    bpy.data.images["Render Result"].save_render(str(path), scene=scene)
    with OpenEXR.File(str(path)) as f:
        chans = {}
        for part in f.parts:
            for name, ch in part.channels.items():
                chans[name.split(".", 1)[-1]] = np.array(ch.pixels)
    path.unlink()
    return chans


def render_rgb(scene, bs: geometry.BlenderScene, cfg, seed: int, scratch: Path) -> tuple[np.ndarray, float]:
    """Render the RGB pass; return ((H, W, 3) float32 linear RGB, seconds)."""
    session.rgb_state(scene, cfg, seed)
    geometry.set_proxies_visible(bs, False)
    t = time.perf_counter()
    chans = _render(scene, scratch / "rgb.exr", "rgb")
    combined = chans["Combined"]
    return np.ascontiguousarray(combined[..., :3], np.float32), time.perf_counter() - t


def _one_x_size(scene) -> tuple[int, int]:
    r = scene.render
    return r.resolution_x * r.resolution_percentage // 100, r.resolution_y * r.resolution_percentage // 100


def render_labels(scene, bs: geometry.BlenderScene, k: np.ndarray, scratch: Path, supersample: int = 1) -> LabelPasses:
    """Render the label and real passes for the current camera.

    Parameters
    ----------
    k : (3, 3) float64
        Camera intrinsics, used to turn planar depth into range along each pixel ray.
    supersample : int
        Odd factor: the label pass is rendered at ``supersample`` times the resolution and
        reduced by a per-pixel majority vote (1: one sample at each pixel centre).

    Notes
    -----
    One scene state serves both passes (:mod:`generator.blender.label_shader`): the proxies
    are visible, opaque to off-centre rays and transparent to pixel-centre rays. With
    ``supersample`` 1 a single 1x render gives everything. Otherwise the ``k``-times render
    gives the labels and a 1x render right after it -- only the resolution changes, so Cycles
    neither re-syncs the scene nor rebuilds its BVH -- gives the real class and depth. The
    middle samples of the ``k``-times render trace the same pixel centres, but not bit for bit
    (Cycles' raster-to-camera transform rounds differently at another resolution: depth differs
    by ~5e-6 relative, a few silhouette pixels change class), so depth is never taken from it.

    ``seconds`` holds ``label_pass`` (the supersampled render, its read back and the vote; 0
    at 1x) and ``real_pass`` (the 1x render and its read back).
    """
    w, h = _one_x_size(scene)
    label_shader.mark_proxies(bs.proxy_objects)
    session.label_state(scene, label_shader.label_material(w, h), label_world())
    geometry.set_proxies_visible(bs, True)
    secs = {"label_pass": 0.0}
    try:
        if supersample > 1:
            t = time.perf_counter()
            with session.supersampled(scene, supersample):
                fine = _render(scene, scratch / "label.exr")
            fine_class, fine_instance, _, _ = label_colour.decode(fine["Combined"], "label pass")
            del fine
            class_id, instance = majority_labels(fine_class, fine_instance, supersample)
            secs["label_pass"] = time.perf_counter() - t
        t = time.perf_counter()
        real = _render(scene, scratch / "real.exr")
        secs["real_pass"] = time.perf_counter() - t
    finally:
        geometry.set_proxies_visible(bs, False)
    centre_class, centre_instance, real_class, real_instance = label_colour.decode(real["Combined"], "real pass")
    if supersample == 1:
        class_id, instance = centre_class, centre_instance
    lost = int(np.count_nonzero(real_class == 0))
    if lost:  # every surface and the sky have a class: 0 means Cycles stopped the ray inside the proxies
        log.warning("real pass: %d pixel-centre rays crossed more than %d label proxies and found no surface",
                    lost, label_shader.MAX_PROXY_CROSSINGS)
    z = real["Depth.Z"] if "Depth.Z" in real else real["Z"]
    cos = rig.pixel_rays(k, w, h)[..., 2]
    depth = (z / cos).astype(np.float32)
    depth[z >= SKY_Z] = np.inf
    return LabelPasses(class_id, instance, real_class, real_instance, depth, secs)
