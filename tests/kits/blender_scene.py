"""The street tests' "reaches Blender triangle for triangle" check (needs bpy: mark the test blender)."""

from __future__ import annotations

import numpy as np


def blender_matches_scene(spec, scene, tmp_path) -> None:
    """Blender's evaluated geometry of ``scene`` has its triangle count and bounds."""
    from generator.blender.renderer import Renderer
    from generator.spec.render import load_render_config

    n, bounds = Renderer(scene, spec, load_render_config("test"), tmp_path).evaluated_geometry()
    assert n == len(scene.faces)
    v = scene.vertices.astype(np.float64)
    assert np.allclose(bounds, [v.min(0), v.max(0)], atol=1e-3)
