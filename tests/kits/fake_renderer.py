"""A renderer without Blender: what :func:`generator.jobs.variants.render_frame` asks of one, so the
image writers (EXR, PNG, metadata JSON) run for real on any spec in a test."""

from __future__ import annotations

import numpy as np

from generator.world.rig import intrinsics


class FlatLabels:
    """Label passes of a flat view: road in the lower half, sky above, depth 5 m (sky: inf)."""

    def __init__(self, h: int, w: int):
        from generator.labels import class_table

        t = class_table()
        self.class_id = np.full((h, w), t.id("road"), np.uint8)
        self.class_id[: h // 2] = t.id("sky")
        self.instance = np.zeros((h, w), np.uint32)
        self.depth = np.where(self.class_id == t.id("sky"), np.inf, 5.0).astype(np.float32)
        self.seconds = {"real_pass": 0.0, "label_pass": 0.0}


class FakeRenderer:
    """Renders grey RGB and :class:`FlatLabels` at ``h`` x ``w`` pixels (90 degree field of view)."""

    device, blender_version = "cpu", None

    def __init__(self, h: int, w: int):
        self.k, self.h, self.w = intrinsics(90.0, w, h), h, w

    def place_camera(self, T):
        pass

    def render_labels(self):
        return FlatLabels(self.h, self.w)

    def set_conditions(self, light, wetness, puddles):
        return {"wetness": wetness}

    def render_rgb(self, seed):
        return np.full((self.h, self.w, 3), 0.18, np.float32), 0.0
