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

The label state differs from the RGB state in the label switch (every material emits its
label, :mod:`generator.blender.materials`), Cycles' sampling, filter, bounce and seed settings,
motion blur (off), the proxies' ray visibility and the resolution; the world stays (sky is where
the Z pass reports no hit). Switching states costs Cycles a re-sync (motion blur, visibility), so
:func:`render_label_batch` renders the label passes of several images behind one switch.

Depth is converted from Cycles' planar Z to the distance along the pixel's ray
(range, metres) so it compares directly with LiDAR range; sky pixels get +inf.
Background mode has no pixels in "Render Result", so each render is saved with
``save_render`` to an uncompressed float EXR in a scratch folder and read back.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import OpenEXR

from generator.blender import geometry, session
from generator.blender.bpy_guard import bpy
from generator.labels import class_table
from generator.labels.supersample import majority_labels
from generator.world import rig

SKY_Z = 1e9
#: Native class of pixels whose ray hits nothing.
SKY_CLASS = class_table().id("sky")


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


def _integers(rgba: np.ndarray, sky: np.ndarray, what: str) -> tuple[np.ndarray, np.ndarray]:
    """Class and instance per pixel of a label-material render; ``sky`` pixels (nothing hit) get the
    sky class and instance 0 (the background shows the RGB world's radiance, which is not a label)."""
    vals = rgba[..., :2]
    ints = np.rint(vals)
    bad = (np.abs(vals - ints) > 1e-3).any(axis=-1) & ~sky
    if bad.any():
        raise RuntimeError(f"{what}: {int(bad.sum())} pixel values are not integers: labels would be blended")
    cls, inst = ints[..., 0].astype(np.uint8), ints[..., 1].astype(np.uint16)
    cls[sky], inst[sky] = SKY_CLASS, 0
    return cls, inst


def label_samples(chans: dict[str, np.ndarray], what: str = "label pass") -> tuple[np.ndarray, np.ndarray]:
    """(H, W) uint8 class and (H, W) uint16 instance of one label-material render's channels (as
    read by :func:`_render`): exact integers, sky where the ray hit nothing."""
    return _integers(chans["Combined"], _z(chans) >= SKY_Z, what)


def _z(chans: dict[str, np.ndarray]) -> np.ndarray:
    return chans["Depth.Z"] if "Depth.Z" in chans else chans["Z"]


def render_labels(scene, bs: geometry.BlenderScene, k: np.ndarray, scratch: Path, supersample: int = 1) -> LabelPasses:
    """Render the real and label passes for the current camera (:func:`render_label_batch` of one pose)."""
    return render_label_batch(scene, bs, k, scratch, [lambda: None], supersample)[0]


def render_label_batch(scene, bs: geometry.BlenderScene, k: np.ndarray, scratch: Path,
                       poses: Sequence[Callable[[], object]], supersample: int = 1) -> list[LabelPasses]:
    """Render the real and label passes of several camera poses with one switch into the label state.

    Switching the scene between the RGB and the label state costs Cycles a re-sync (motion blur
    off, then on again before the next RGB render); a batch pays it once. The RGB world stays in
    place: sky is where the Z pass reports no hit, so the sky model's precomputation is never
    redone for labels.

    Parameters
    ----------
    k : (3, 3) float64
        Camera intrinsics, used to turn planar depth into range along each pixel ray.
    poses : sequence of callables
        Each puts the camera (and the actors) where one image is taken; called once before
        that image's real pass and once before its label pass.
    supersample : int
        Odd factor: the label pass is rendered at ``supersample`` times the resolution and
        reduced by a per-pixel majority vote (1: one sample at each pixel centre).

    Returns
    -------
    list of LabelPasses
        One per pose, in order; ``seconds`` holds the pose's own render times (``"real_pass"``,
        ``"label_pass"``: Cycles, EXR read-back, vote) and an equal share of the batch's time
        outside the renders (``"posing"``: posing camera and actors, the proxies' visibility).
        Cycles pays the switch into the label state inside the first real pass, and the switch
        back inside the next RGB render.
    """
    t0 = time.perf_counter()
    session.label_state(scene)
    geometry.set_proxies_visible(bs, False)
    reals, secs = [], [{} for _ in poses]
    for place, sec in zip(poses, secs, strict=False):
        place()
        t = time.perf_counter()
        real = _render(scene, scratch / "real.exr")
        real_class, real_instance = label_samples(real, "real pass")
        z = _z(real)
        h, w = real_class.shape
        depth = (z / rig.pixel_rays(k, w, h)[..., 2]).astype(np.float32)
        depth[z >= SKY_Z] = np.inf
        reals.append((real_class, real_instance, depth))
        sec["real_pass"] = time.perf_counter() - t
    geometry.set_proxies_visible(bs, True)
    out = []
    with session.supersampled(scene, supersample):
        for place, sec, (real_class, real_instance, depth) in zip(poses, secs, reals, strict=False):
            place()
            t = time.perf_counter()
            fine_class, fine_instance = label_samples(_render(scene, scratch / "label.exr"))
            class_id, instance = majority_labels(fine_class, fine_instance, supersample)
            sec["label_pass"] = time.perf_counter() - t
            out.append(LabelPasses(class_id, instance, real_class, real_instance, depth, sec))
    geometry.set_proxies_visible(bs, False)
    posing = (time.perf_counter() - t0 - sum(s["real_pass"] + s["label_pass"] for s in secs)) / max(len(poses), 1)
    for sec in secs:
        sec["posing"] = posing
    return out
