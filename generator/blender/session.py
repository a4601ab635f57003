"""Blender session: an empty scene configured for Cycles from a RenderConfig.

Two render states share one scene: the RGB pass (the config's samples, bounces,
filter, denoiser, motion blur) and the label pass (1 sample, no bounces, a box filter of
minimal width, no denoising, no motion blur, the label switch :data:`controls.LABEL` at 1: every
material emits its label). A state only writes the switch when it changes. The switch replaced
the view layer's material override, which made Cycles recompile every shader and re-sync every
mesh on each write, in the label pass and again in the next RGB pass.
"""

from __future__ import annotations

import logging
from contextlib import contextmanager

from generator.blender import controls, motion
from generator.blender.bpy_guard import bpy
from generator.spec.render import RenderConfig

log = logging.getLogger(__name__)


def reset() -> bpy.types.Scene:
    """Start from an empty factory scene and return it."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    return bpy.context.scene


#: GPU backends in order of preference (OptiX first: the paper's, and the only one with its denoiser)
BACKENDS = ("OPTIX", "CUDA", "HIP", "ONEAPI", "METAL")
#: Scene property holding the denoiser :func:`configure` chose (read by :func:`rgb_state`)
DENOISER_KEY = "urbangen_denoiser"


def _use_backend(backend: str) -> bool:
    """Switch Cycles to ``backend`` and enable its GPUs; False if it has none here."""
    prefs = bpy.context.preferences.addons["cycles"].preferences
    try:
        prefs.compute_device_type = backend
    except TypeError:
        return False
    prefs.get_devices()
    if not any(d.type == backend for d in prefs.devices):
        return False
    for d in prefs.devices:
        d.use = d.type != "CPU"
    return True


def _gpu_available() -> bool:
    return any(_use_backend(b) for b in BACKENDS)


def _denoiser(scene: bpy.types.Scene, cfg: RenderConfig) -> str:
    """The Cycles denoiser for ``cfg`` ("" for none): OptiX where an OptiX device exists (it denoises
    on that GPU even when the render runs on the CPU), else OpenImageDenoise with a warning."""
    if cfg.denoiser == "none":
        return ""
    if cfg.denoiser == "optix":
        if _use_backend("OPTIX"):
            try:
                scene.cycles.denoiser = "OPTIX"
                scene.cycles.denoising_use_gpu = True
                return "OPTIX"
            except TypeError:
                pass
        log.warning("render config %s asks for the OptiX denoiser but no OptiX device (an NVIDIA RTX GPU with its "
                    "driver) was found; denoising with OpenImageDenoise on the CPU instead", cfg.name)
    return "OPENIMAGEDENOISE"


def configure(scene: bpy.types.Scene, cfg: RenderConfig) -> str:
    """Apply ``cfg`` to ``scene``; return the device actually used ("CPU" or "GPU").

    A GPU or the OptiX denoiser asked for where none exists falls back to the CPU (OpenImageDenoise)
    with a warning, so a config written for a GPU render node still runs anywhere.
    """
    scene.render.engine = "CYCLES"
    device = "CPU"
    if cfg.device == "gpu":
        if _gpu_available():
            device = "GPU"
        else:
            log.warning("render config %s asks for a GPU but none was found (no OptiX/CUDA/HIP/oneAPI/Metal "
                        "device); rendering on the CPU instead", cfg.name)
    scene.cycles.device = device
    scene[DENOISER_KEY] = _denoiser(scene, cfg)
    r = scene.render
    r.resolution_x, r.resolution_y = cfg.width, cfg.height
    r.resolution_percentage = 100
    r.use_persistent_data = cfg.persistent_data
    r.threads_mode = "FIXED" if cfg.threads > 0 else "AUTO"
    if cfg.threads > 0:
        r.threads = cfg.threads
    r.dither_intensity = 0.0
    r.use_compositing = False
    r.use_sequencer = False
    r.film_transparent = False
    r.use_motion_blur = False
    s = r.image_settings
    s.media_type = "MULTI_LAYER_IMAGE"
    s.color_depth = "32"
    s.exr_codec = "NONE"
    scene.view_layers[0].use_pass_z = True
    scene[controls.LABEL] = 0.0
    return device


def rgb_state(scene: bpy.types.Scene, cfg: RenderConfig, seed: int) -> None:
    """Settings of the RGB pass."""
    c = scene.cycles
    c.samples = cfg.samples
    c.use_adaptive_sampling = cfg.adaptive_threshold > 0
    if cfg.adaptive_threshold > 0:
        c.adaptive_threshold = cfg.adaptive_threshold
    c.max_bounces = cfg.max_bounces
    c.diffuse_bounces = min(cfg.max_bounces, 4)
    c.glossy_bounces = min(cfg.max_bounces, 4)
    c.transmission_bounces = min(cfg.max_bounces, 8)
    c.transparent_max_bounces = 8
    c.caustics_reflective = False
    c.caustics_refractive = False
    c.sample_clamp_indirect = 10.0
    c.pixel_filter_type = "BLACKMAN_HARRIS"
    c.filter_width = 1.5
    denoiser = scene.get(DENOISER_KEY) or ""
    c.use_denoising = bool(denoiser)
    if c.use_denoising:
        c.denoiser = denoiser
        c.denoising_quality = cfg.denoiser_quality.upper()
    c.seed = seed % (2**31 - 1)
    blur = cfg.motion_blur.enabled
    scene.render.use_motion_blur = blur
    if blur:  # the exposure spans the keys around the image instant (generator.blender.motion)
        scene.render.motion_blur_shutter = motion.SHUTTER_FRAMES
        scene.render.motion_blur_position = "CENTER"
    vl = scene.view_layers[0]
    if vl.material_override is not None:
        vl.material_override = None
    _switch(scene, 0.0)


def _switch(scene: bpy.types.Scene, value: float) -> None:
    """Set the label switch (and tag the scene) only when it changes."""
    if scene.get(controls.LABEL) != value:
        scene[controls.LABEL] = value
        scene.update_tag()


def label_state(scene: bpy.types.Scene, material=None) -> None:
    """Settings of the label pass: exact integers per pixel (every material emits them with the
    label switch on).

    The world is left as it is: what the camera sees of it is sky, told apart by the Z pass.
    ``material``: a label material to set as the view layer's override instead (the old way,
    for benches that compare against it).
    """
    c = scene.cycles
    c.samples = 1
    c.use_adaptive_sampling = False
    c.max_bounces = 0
    c.transparent_max_bounces = 0
    c.use_denoising = False
    c.pixel_filter_type = "BOX"
    c.filter_width = 0.01
    c.seed = 0
    scene.render.use_motion_blur = False  # labels at the image instant: never blended
    vl = scene.view_layers[0]
    if vl.material_override != material:
        vl.material_override = material
    _switch(scene, 1.0)


@contextmanager
def supersampled(scene: bpy.types.Scene, k: int):
    """Render at ``k`` times the configured resolution inside the block (label pass).

    The image plane and field of view are unchanged, so with ``k`` odd the middle sample of
    every ``k x k`` block is the centre of the pixel it belongs to. The depth pass stays on: it
    tells the sky samples apart.
    """
    if k == 1:
        yield
        return
    r = scene.render
    percentage = r.resolution_percentage
    r.resolution_percentage = percentage * k
    try:
        yield
    finally:
        r.resolution_percentage = percentage
