"""A walker's gait in the world in time (generator/world/actors.py ``Gait``): the phase mesh it shows
follows the distance it has walked, and its box is the extent of that mesh at every instant."""

from __future__ import annotations

import numpy as np
import pytest

from generator.detection.subjects import subjects
from generator.world.actors import World
from kits.scene_kit import scene_of
from kits.walker_world import straight, walker


@pytest.fixture(scope="module")
def ground():
    from generator.geometry import rect

    return scene_of([("ground", rect(-50, -50, 50, 50, 0.0, "road", "asphalt"), 0)])


def test_the_phase_follows_the_walked_distance_and_repeats_every_stride():
    protos: dict = {}
    fast = walker(protos, straight((0.0, 0.0, 0.0), (1.4, 0.0)))
    slow = walker(protos, straight((0.0, 0.0, 0.0), (0.7, 0.0), seconds=8.0))
    stride = fast.gait.stride_m
    assert 0.65 * 1.75 < stride < 0.85 * 1.75                # two steps: about 0.7-0.8 of body height
    n = len(fast.gait.keys)
    t_cycle = stride / 1.4
    seen = [fast.prototype_at(k * t_cycle / n) for k in range(n)]
    assert seen == list(fast.gait.keys)                      # every phase in turn over one stride
    for t in (0.13, 0.61, 1.0):
        assert fast.prototype_at(t) == fast.prototype_at(t + t_cycle)          # periodic in distance
        assert slow.prototype_at(2 * t) == fast.prototype_at(t)                # the same distance, the same pose
    meshes = {protos[k].vertices.tobytes() for k in fast.gait.keys}
    assert len(meshes) == n                                  # the limbs move: no two phases alike
    assert all(np.array_equal(protos[k].faces, protos[fast.prototype].faces) for k in fast.gait.keys)


def test_a_walker_who_stands_still_keeps_its_pose():
    protos: dict = {}
    still = walker(protos, straight((3.0, 1.0, 0.0), (0.0, 0.0)))
    assert {still.prototype_at(t) for t in np.linspace(0, 3, 13)} == {still.gait.keys[0]}


def test_the_box_is_the_extent_of_the_mesh_shown_at_every_instant(ground):
    protos: dict = {}
    a = walker(protos, straight((2.0, -1.0, 0.0), (0.6, 1.2)))
    world = World(ground, [a], protos, {}, None, 4.0)
    (sub,) = subjects(ground, world)
    sizes = []
    for t in np.linspace(0.1, 2.1, 41):       # (central differences need a sample either side)
        b = a.box(t)
        v, _ = sub.triangles(t)                              # the detection subject's triangles then
        T = a.track.pose(t)[0]
        local = (v - T[:3, 3]) @ T[:3, :3]
        m = protos[a.prototype_at(t)]
        np.testing.assert_allclose(local, m.vertices, atol=1e-9)
        lo, hi = local.min(0), local.max(0)
        np.testing.assert_allclose(b.size, hi - lo, atol=1e-9)
        np.testing.assert_allclose(b.center, T[:3, :3] @ ((lo + hi) / 2) + T[:3, 3], atol=1e-9)
        sizes.append(b.size[0])
        # the box's velocity is the body's, not the swinging limbs'
        np.testing.assert_allclose(sub.motion(t)[0][:2], [0.6, 1.2], atol=1e-6)
    assert np.ptp(sizes) > 0.3                               # a stride's length, then feet together


def test_a_rigid_actor_shows_its_one_mesh_in_its_one_box():
    from generator.world.actors import Actor

    a = Actor(0, "a", "car", "car", 5, "car", (4.0, 2.0, 1.5), (0.0, 0.0, 0.75), straight((0.0, 0.0, 0.0), (1.0, 0.0)))
    assert a.gait is None and a.prototype_at(1.0) == "car"
    assert a.box(1.0).size == (4.0, 2.0, 1.5)
