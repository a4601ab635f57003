"""A walker's flow: surface points move with the body and with their limb (generator/motion/articulation.py)."""

from __future__ import annotations

import numpy as np

from generator.motion.articulation import carry
from generator.world.actors import World
from generator.world.kinematics import movers
from kits.walker_world import straight, walker


def test_points_of_a_walker_land_on_the_mesh_it_shows_later_and_limbs_move_more_than_the_body():
    protos: dict = {}
    a = walker(protos, straight((0.0, 0.0, 0.0), (1.4, 0.0)))
    world = World(None, [a], protos, {}, None, 4.0)
    t0, t1 = 1.0, 1.1
    (m,) = movers(world, t0, t1)
    assert m.meshes is not None                                  # the phase changed in 0.1 s
    m0, m1 = protos[a.prototype_at(t0)], protos[a.prototype_at(t1)]
    rng = np.random.default_rng(0)
    f = rng.integers(0, len(m0.faces), 400)
    w = rng.dirichlet((1, 1, 1), 400)
    local0 = np.einsum("nc,ncj->nj", w, m0.vertices[m0.faces[f]])   # points on the surface at t0
    world0 = local0 @ m.T0[:3, :3].T + m.T0[:3, 3]
    got = carry(m, world0)
    expect = np.einsum("nc,ncj->nj", w, m1.vertices[m1.faces[f]]) @ m.T1[:3, :3].T + m.T1[:3, 3]
    close = np.linalg.norm(got - expect, axis=1) < 1e-6
    assert close.mean() > 0.97                                   # (points where parts touch may pick the other)
    rigid = world0 @ m.M[:3, :3].T + m.M[:3, 3]
    limb = np.linalg.norm(got - rigid, axis=1)
    assert limb.max() > 0.05 and np.median(limb) < 0.04           # a swinging foot or hand; the torso bobs a little
    (still,) = movers(world, t0, t0)
    assert still.meshes is None
