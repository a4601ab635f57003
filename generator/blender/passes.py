"""Render passes as numpy arrays.

* RGB pass: the config's Cycles settings, label proxies hidden -> linear RGB.
* Real pass: label material, 1 sample, proxies hidden -> class and instance of the real
  surface at each pixel centre and its planar depth.
* Label pass: the same with the proxies shown -> the mask class and instance. With a
  supersampling factor ``k`` (the config's ``label_supersample``, odd) it is rendered at ``k``
  times the resolution and each pixel takes the majority class of its ``k x k`` samples
  (:func:`generator.labels.supersample.majority_labels`): thin markings stop flickering as the
  camera moves, and every pixel still holds one exact class id. The real pass (depth, the
  class a ray through the pixel centre hits) stays at 1x: depth is never voted or blended.

Depth is converted from Cycles' planar Z to the distance along the pixel's ray
(range, metres) so it compares directly with LiDAR range; sky pixels get +inf.
Background mode has no pixels in "Render Result", so each render is saved with
``save_render`` to an uncompressed float EXR in a scratch folder and read back.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import OpenEXR

from generator.world import rig
from generator.blender import geometry, session
from generator.blender.bpy_guard import bpy
from generator.blender.materials import label_material, label_world
from generator.labels.supersample import majority_labels

SKY_Z = 1e9


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


def _integers(rgba: np.ndarray, what: str) -> tuple[np.ndarray, np.ndarray]:
    vals = rgba[..., :2]
    ints = np.rint(vals)
    bad = np.abs(vals - ints) > 1e-3
    if bad.any():
        raise RuntimeError(f"{what}: {int(bad.sum())} pixel values are not integers: labels would be blended")
    return ints[..., 0].astype(np.uint8), ints[..., 1].astype(np.uint16)


def render_labels(scene, bs: geometry.BlenderScene, k: np.ndarray, scratch: Path, supersample: int = 1) -> LabelPasses:
    """Render the real and label passes for the current camera.

    Parameters
    ----------
    k : (3, 3) float64
        Camera intrinsics, used to turn planar depth into range along each pixel ray.
    supersample : int
        Odd factor: the label pass is rendered at ``supersample`` times the resolution and
        reduced by a per-pixel majority vote (1: one sample at each pixel centre).
    """
    session.label_state(scene, label_material(), label_world())
    secs = {}
    geometry.set_proxies_visible(bs, False)
    t = time.perf_counter()
    real = _render(scene, scratch / "real.exr")
    secs["real_pass"] = time.perf_counter() - t
    geometry.set_proxies_visible(bs, True)
    t = time.perf_counter()
    with session.supersampled(scene, supersample):
        lab = _render(scene, scratch / "label.exr")
    fine_class, fine_instance = _integers(lab["Combined"], "label pass")
    del lab
    class_id, instance = majority_labels(fine_class, fine_instance, supersample)
    secs["label_pass"] = time.perf_counter() - t
    geometry.set_proxies_visible(bs, False)
    real_class, real_instance = _integers(real["Combined"], "real pass")
    h, w = real_class.shape
    z = real["Depth.Z"] if "Depth.Z" in real else real["Z"]
    cos = rig.pixel_rays(k, w, h)[..., 2]
    depth = (z / cos).astype(np.float32)
    depth[z >= SKY_Z] = np.inf
    return LabelPasses(class_id, instance, real_class, real_instance, depth, secs)
