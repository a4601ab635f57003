"""Visibility per image from the instance pass and the things' own triangles (issue 26, item 2)."""

from __future__ import annotations

import numpy as np
import pytest

from generator.detection import subjects
from generator.detection.visibility import difficulty, image_boxes, nuscenes_bin, occlusion_level
from kits.box_kit import CUT, HEIGHT, HIDDEN, TRUCK, WIDTH, box_scene, instance_pass


@pytest.fixture(scope="module")
def seen():
    bs = box_scene()
    inst = instance_pass(bs.scene, bs.T_world_camera, bs.K, WIDTH, HEIGHT)
    boxes = {b.track_id: b for b in image_boxes(subjects(bs.scene), 0.0, bs.T_world_camera, bs.K, inst)}
    return bs, inst, boxes


def test_a_car_half_hidden_behind_a_truck_is_half_visible(seen):
    bs, _, boxes = seen
    assert bs.hidden_share == pytest.approx(0.5, abs=1e-6)       # the built scene: the truck's edge halves it
    car = boxes[HIDDEN]
    assert car.visibility == pytest.approx(0.5, abs=0.03)
    assert car.truncation == 0.0 and car.occlusion == 1 and car.nuscenes_visibility == "2"
    # the visible box is the right half of the amodal one, same rows
    assert car.bbox_visible[[1, 3]].tolist() == car.bbox_amodal[[1, 3]].tolist()
    assert car.bbox_amodal[0] < car.bbox_visible[0] < car.bbox_visible[2] == car.bbox_amodal[2]
    truck = boxes[TRUCK]
    assert truck.visibility == 1.0 and truck.occlusion == 0 and truck.difficulty == 0


def test_a_car_cut_by_the_border_has_the_analytic_truncation(seen):
    bs, _, boxes = seen
    car = boxes[CUT]
    assert 0.3 < bs.cut_truncation < 0.9
    assert car.truncation == pytest.approx(bs.cut_truncation, abs=0.01)
    assert car.visibility == 1.0 and car.bbox_amodal[0] == 0.0
    assert car.difficulty == -1  # truncated beyond KITTI's hard limit (0.5)


def test_visible_pixels_are_the_instance_pass_and_lie_in_the_footprint(seen):
    _, inst, boxes = seen
    for tid, b in boxes.items():
        assert b.pixels_visible == int((inst == tid).sum())
        assert b.pixels_visible <= b.pixels_amodal


def test_nothing_in_view_gives_no_boxes(seen):
    bs, inst, _ = seen
    back = bs.T_world_camera @ np.diag([-1.0, 1.0, -1.0, 1.0])  # turned round: the things are behind
    assert image_boxes(subjects(bs.scene), 0.0, back, bs.K, np.zeros_like(inst)) == []


def test_kitti_levels_and_nuscenes_bins():
    assert occlusion_level(1.0, 10) == 0 and occlusion_level(0.6, 10) == 1 and occlusion_level(0.1, 10) == 2
    assert occlusion_level(0.0, 0) == 3
    assert difficulty(40.5, 0, 0.15) == 0 and difficulty(40, 0, 0.0) == 1 and difficulty(30, 2, 0.4) == 2
    assert difficulty(25, 0, 0.0) == -1 and difficulty(100, 3, 0.0) == -1 and difficulty(100, 0, 0.6) == -1
    assert [nuscenes_bin(v) for v in (0.0, 0.39, 0.4, 0.59, 0.6, 0.79, 0.8, 1.0)] == list("11223344")
