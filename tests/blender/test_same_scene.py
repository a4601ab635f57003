"""The "same scene" guarantee on the test town: Blender's evaluated geometry equals the SceneModel,
and Embree (what the LiDAR casts with) agrees with Blender's own ray casts."""

from __future__ import annotations

import numpy as np
import pytest

from generator.lidar.caster import EmbreeCaster
from generator.lidar.sensors import sensor_for_spec
from generator.world.rig import Rig

pytestmark = pytest.mark.blender


@pytest.fixture(scope="module")
def town(test_spec, test_scene, tmp_path_factory):
    from generator.blender.renderer import Renderer
    from generator.spec.render import load_render_config

    return test_scene, Renderer(test_scene, test_spec, load_render_config("test"), tmp_path_factory.mktemp("s"))


def test_blender_triangles_and_bounds_equal_the_scene_model(town):
    scene, renderer = town
    n, bounds = renderer.evaluated_geometry()
    assert n == len(scene.faces)
    v = scene.vertices.astype(np.float64)
    assert np.allclose(bounds, [v.min(0), v.max(0)], atol=1e-3)


def test_embree_distances_equal_blender_ray_cast(town, test_spec):
    from generator.blender.bpy_guard import bpy, mathutils

    scene, renderer = town
    sensor = sensor_for_spec(test_spec)
    origins, dirs, _ = sensor.local_rays()
    T = np.asarray(scene.paths[0].at(5.0)[0][0])
    pose = np.eye(4)
    pose[:3, 3] = T
    T_world = pose @ Rig.from_spec(test_spec).T_ego_lidar
    o = (origins.reshape(-1, 3) @ T_world[:3, :3].T + T_world[:3, 3])
    d = dirs.reshape(-1, 3) @ T_world[:3, :3].T
    pick = np.random.default_rng(0).choice(len(o), 3000, replace=False)
    o, d = o[pick], d[pick]
    dist, _ = EmbreeCaster.from_scene(scene).intersect(o, d, 120.0)

    renderer.handles.proxies.hide_viewport = True  # ray_cast sees viewport visibility: hulls are not real
    bscene = renderer.bscene
    depsgraph = bpy.context.evaluated_depsgraph_get()
    depsgraph.update()
    blender = np.full(len(o), np.inf)
    for i, (oi, di) in enumerate(zip(o, d, strict=False)):
        hit, loc, *_ = bscene.ray_cast(depsgraph, mathutils.Vector(oi), mathutils.Vector(di), distance=120.0)
        if hit:
            blender[i] = (loc - mathutils.Vector(oi)).length
    renderer.handles.proxies.hide_viewport = False
    both = np.isfinite(dist) & np.isfinite(blender)
    assert both.sum() > 2000
    assert np.array_equal(np.isfinite(dist), np.isfinite(blender)), "hit/miss must agree"
    assert np.abs(dist[both] - blender[both]).max() <= 1e-3
