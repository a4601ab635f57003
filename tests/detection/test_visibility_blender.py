"""The visibility of the built scene from Blender's own label pass (the pass generate renders)."""

from __future__ import annotations

import dataclasses

import pytest

from generator.detection import subjects
from generator.detection.visibility import image_boxes
from kits.box_kit import CUT, HIDDEN, TRUCK, box_scene

pytestmark = pytest.mark.blender


@pytest.fixture(scope="module")
def rendered(tmp_path_factory, test_spec):
    from generator.blender.renderer import Renderer
    from generator.spec.render import load_render_config

    cfg = dataclasses.replace(load_render_config("test"), resolution=(320, 240))
    bs = box_scene(test_spec.sensors.camera.hfov_deg, 320, 240)
    r = Renderer(bs.scene, test_spec, cfg, tmp_path_factory.mktemp("scratch"))
    r.place_camera(bs.T_world_camera)
    labels = r.render_labels()
    return bs, r.k, labels.instance


def test_blenders_instance_pass_gives_the_analytic_visibility(rendered):
    bs, K, instance = rendered
    assert bs.hidden_share == pytest.approx(0.5, abs=1e-6)
    boxes = {b.track_id: b for b in image_boxes(subjects(bs.scene), 0.0, bs.T_world_camera, K, instance)}
    assert boxes[HIDDEN].visibility == pytest.approx(0.5, abs=0.04)
    assert boxes[CUT].truncation == pytest.approx(bs.cut_truncation, abs=0.01)
    assert boxes[TRUCK].visibility > 0.97 and boxes[CUT].visibility > 0.97
