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


def test_lidar_scene_flow_moves_a_walkers_points_onto_its_later_phase_mesh():
    from generator.geometry import rect
    from generator.lidar.scan import Scanner
    from generator.lidar.sensors import load_preset
    from generator.motion.scene_flow import SceneFlow
    from generator.world import rig
    from kits.scene_kit import scene_of

    s = load_preset("hdl64e")
    ground = scene_of([("ground", rect(-60, -60, 60, 60, 0.0, "road", "asphalt"), 0)])
    protos: dict = {}
    a = walker(protos, straight((5.0, -1.5, 0.0), (0.0, 1.4)), instance_id=77)
    mount = rig.mount((0, 0, 1.73), (0, 0, 0))
    t0, dt = 1.0, 0.1
    with Scanner(ground, s, threads=1, world=World(ground, [a], protos, {}, None, 4.0)) as sc:
        p = sc.scan(np.stack([mount] * s.azimuth_steps), t0=t0).points
    p = p[p["instance"] == 77]
    assert len(p) > 300

    def ego(t):
        return np.repeat(np.eye(4)[None], len(np.atleast_1d(t)), 0)

    def landed(prototypes):
        with SceneFlow(ego, mount, [a], s.column_time(), dt, threads=1, prototypes=prototypes) as sf:
            obj, _ = sf.flow(p["x"], p["y"], p["z"], p["instance"], p["column"], t0)
        X = np.stack([p["x"], p["y"], p["z"]], 1).astype(np.float64) + obj + mount[:3, 3]
        t1 = t0 + s.column_time()[p["column"]] + dt
        T = a.track.pose(t1)
        local = np.einsum("kji,kj->ki", T[:, :3, :3], X - T[:, :3, 3])
        mesh = np.array([protos[a.prototype_at(t)].vertices for t in t1])     # (n, V, 3) the phase shown then
        faces = protos[a.prototype].faces
        # per point: the smallest distance to the plane of a triangle it lies near (within its circumradius)
        best = np.full(len(local), np.inf)
        for f in faces:
            tri = mesh[:, f]
            n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
            n /= np.linalg.norm(n, axis=1, keepdims=True) + 1e-12
            plane = np.abs(((local - tri[:, 0]) * n).sum(1))
            c = tri.mean(1)
            inside = np.linalg.norm(local - c, axis=1) < np.linalg.norm(tri - c[:, None], axis=2).max(1)
            best = np.where(inside, np.minimum(best, plane), best)
        return best

    with_limbs, rigid = landed(protos), landed(None)
    assert np.mean(with_limbs < 2e-3) > 0.95
    assert np.mean(rigid < 2e-3) < np.mean(with_limbs < 2e-3) - 0.1    # the body's motion alone leaves limbs behind
