"""The supersampled label pass in Blender: a majority vote over exactly the samples of a k-times
finer image, centred on the pixels of the 1x pass, and nothing else in the frame changes."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from generator.labels import class_table
from generator.labels.supersample import majority_labels
from generator.world.rig import Rig

pytestmark = pytest.mark.blender

MARKINGS = [class_table().id("road_marking"), class_table().id("crosswalk")]


@pytest.fixture(scope="module")
def renders(test_spec, test_scene, tmp_path_factory):
    from generator.blender import passes
    from generator.blender.renderer import Renderer
    from generator.spec.render import load_render_config

    base = dataclasses.replace(load_render_config("test"), resolution=(96, 64), label_supersample=3)
    T = Rig.from_spec(test_spec, test_scene).frame(1).T_world_camera
    r = Renderer(test_scene, test_spec, base, tmp_path_factory.mktemp("a"))
    r.place_camera(T)
    l3 = r.render_labels()
    l1 = passes.render_labels(r.bscene, r.handles, r.k, r.scratch, 1)
    rgb, _ = r.render_rgb(seed=0)
    fine = Renderer(test_scene, test_spec, dataclasses.replace(base, resolution=(288, 192), label_supersample=1),
                    tmp_path_factory.mktemp("b"))
    fine.place_camera(T)
    return l3, l1, rgb, fine.render_labels()


def test_vote_is_over_the_samples_of_a_finer_render(renders):
    l3, _, _, fine = renders
    c, i = majority_labels(fine.class_id, fine.instance, 3)
    assert np.array_equal(c, l3.class_id)
    assert np.array_equal(i, l3.instance)


def test_middle_samples_are_the_pixel_centres_of_the_1x_pass(renders):
    _, l1, _, fine = renders
    assert (fine.class_id[1::3, 1::3] == l1.class_id).mean() > 0.999
    assert (fine.instance[1::3, 1::3] == l1.instance).mean() > 0.999


def test_supersampling_changes_only_the_labels_and_only_at_edges(renders):
    l3, l1, rgb, _ = renders
    assert l3.class_id.shape == l1.class_id.shape == rgb.shape[:2] == (64, 96)  # resolution restored for the RGB pass
    assert l3.class_id.dtype == np.uint8 and l3.instance.dtype == np.uint16
    # the real pass (depth, real class) is the same 1x render either way: depth is never voted
    assert np.array_equal(l3.depth, l1.depth) and np.array_equal(l3.real_class, l1.real_class)
    assert np.isfinite(l3.depth).any()
    differ = l3.class_id != l1.class_id
    assert 0 < differ.mean() < 0.05
    assert np.isin(l3.class_id, MARKINGS).any()
    # a pixel only changes where the 1x labels have an edge next to it
    c = np.pad(l1.class_id, 1, mode="edge")
    edge = np.zeros(l1.class_id.shape, bool)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            edge |= c[1 + dy:65 + dy, 1 + dx:97 + dx] != l1.class_id
    assert not (differ & ~edge).any()
