"""A GPU render config on a machine without a GPU falls back to the CPU and says so (Blender)."""

from __future__ import annotations

import dataclasses
import logging

import pytest

pytestmark = pytest.mark.blender


def test_gpu_request_falls_back_to_cpu_with_a_clear_message(caplog):
    from generator.blender import session
    from generator.blender.session import _gpu_available
    from generator.spec.render import load_render_config

    if _gpu_available():
        pytest.skip("this machine has a GPU")
    scene = session.reset()
    cfg = dataclasses.replace(load_render_config("test"), device="gpu")
    with caplog.at_level(logging.WARNING, logger="generator.blender.session"):
        used = session.configure(scene, cfg)
    assert used == "CPU" and scene.cycles.device == "CPU"
    assert any("asks for a GPU but none was found" in r.getMessage() and "CPU" in r.getMessage()
               for r in caplog.records)


def test_optix_denoiser_falls_back_to_openimagedenoise_with_a_clear_message(caplog):
    """The paper's render path (paper_gpu: GPU + OptiX) runs on a CPU-only node: the RGB pass is still
    denoised, by OpenImageDenoise, and the log says why."""
    from generator.blender import session
    from generator.spec.render import load_render_config

    scene = session.reset()
    cfg = load_render_config("paper_gpu")
    assert cfg.denoiser == "optix" and cfg.device == "gpu"
    if session._use_backend("OPTIX"):
        pytest.skip("this machine has an OptiX device")
    with caplog.at_level(logging.WARNING, logger="generator.blender.session"):
        session.configure(scene, cfg)
        session.rgb_state(scene, cfg, seed=1)
    assert scene.cycles.use_denoising and scene.cycles.denoiser == "OPENIMAGEDENOISE"
    assert any("OptiX denoiser" in r.getMessage() and "OpenImageDenoise" in r.getMessage() for r in caplog.records)


def test_no_denoiser_means_no_denoising():
    from generator.blender import session
    from generator.spec.render import load_render_config

    scene = session.reset()
    cfg = load_render_config("test")
    assert cfg.denoiser == "none"
    session.configure(scene, cfg)
    session.rgb_state(scene, cfg, seed=1)
    assert not scene.cycles.use_denoising
