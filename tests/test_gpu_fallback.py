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
