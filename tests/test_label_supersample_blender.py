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


def _two_scene_states(r, k):
    """The label passes the plain way, two scene states: the real pass with the proxies hidden and
    the label pass with opaque proxies at ``k`` times the resolution (each sample the first hit)."""
    from generator.blender import geometry, passes, session
    from generator.blender.materials import label_material, label_world
    from generator.labels.label_colour import decode

    session.label_state(r.bscene, label_material(), label_world())
    geometry.set_proxies_visible(r.handles, False)
    real = passes._render(r.bscene, r.scratch / "ref_real.exr")
    geometry.set_proxies_visible(r.handles, True)
    with session.supersampled(r.bscene, k):
        fine = passes._render(r.bscene, r.scratch / "ref_label.exr")
    geometry.set_proxies_visible(r.handles, False)
    _, _, real_c, real_i = decode(real["Combined"], "reference real pass")
    _, _, fine_c, fine_i = decode(fine["Combined"], "reference label pass")
    return real_c, real_i, real["Depth.Z"], fine_c, fine_i


@pytest.mark.parametrize("k", [1, 3])
def test_one_scene_state_gives_what_hiding_and_showing_the_proxies_gives(test_spec, test_scene, tmp_path, k):
    """Proxies transparent to pixel-centre rays only: the real pass sees the real geometry behind
    them, the label pass stops at them, exactly as two renders with the proxies hidden / shown."""
    from generator.blender import passes
    from generator.blender.renderer import Renderer
    from generator.spec.render import load_render_config
    from generator.world import rig

    cfg = dataclasses.replace(load_render_config("test"), resolution=(96, 64), label_supersample=k)
    r = Renderer(test_scene, test_spec, cfg, tmp_path)
    r.place_camera(Rig.from_spec(test_spec, test_scene).frame(1).T_world_camera)
    got = r.render_labels()
    real_c, real_i, z, fine_c, fine_i = _two_scene_states(r, k)
    assert np.array_equal(got.real_class, real_c) and np.array_equal(got.real_instance, real_i)
    c, i = majority_labels(fine_c, fine_i, k)
    assert np.array_equal(got.class_id, c) and np.array_equal(got.instance, i)
    depth = z / rig.pixel_rays(r.k, 96, 64)[..., 2]
    sky = z >= passes.SKY_Z
    assert np.array_equal(np.isinf(got.depth), sky)
    # the scene's BVH now holds the (transparent) proxies too: allow float32 rounding, no more
    assert np.allclose(got.depth[~sky], depth[~sky], rtol=1e-6, atol=0)
    # not vacuous: proxies cover some pixel centres, and the real pass saw through them there
    hull = got.class_id != got.real_class
    assert hull.mean() > 0.01
    assert np.isfinite(got.depth[hull]).any()
