"""A walker in a LiDAR sweep: every point lies on the gait phase mesh the world shows at its column's
firing time (generator/lidar/actors.py picks it per column), the one the camera shows then."""

from __future__ import annotations

import numpy as np
import pytest

from generator.geometry import rect
from generator.lidar.scan import Scanner
from generator.lidar.sensors import load_preset
from generator.world import rig
from generator.world.actors import World
from kits.scene_kit import scene_of
from kits.surface_kit import on_surface
from kits.walker_world import straight, walker

H = 1.73


def _on_mesh(points: np.ndarray, mesh, tol: float) -> np.ndarray:
    """(n,) bool: which local points lie on a triangle of ``mesh`` (``tol`` m)."""
    return on_surface(points, mesh.vertices, mesh.faces, tol)


def test_every_point_lies_on_the_phase_mesh_of_its_firing_time():
    """Eight walkers round the sensor, 6 m away, all a stride's same fraction on at t = 0: the sweep reaches
    them 12.5 ms apart, so they show different phases; each point lies on the phase its column saw."""
    s = load_preset("hdl64e")
    ground = scene_of([("ground", rect(-60, -60, 60, 60, 0.0, "road", "asphalt"), 0)])
    protos: dict = {}
    t0, v = 0.4, 1.4
    actors = []
    for i, az in enumerate(np.radians(np.arange(0, 360, 45))):
        c, d = 6.0 * np.array([np.cos(az), np.sin(az), 0.0]), np.array([-np.sin(az), np.cos(az)])
        actors.append(walker(protos, straight(c - np.r_[d, 0.0] * v * (t0 + 0.05), tuple(v * d)), uid=i,
                             instance_id=70 + i))
    world = World(ground, actors, protos, {}, None, 4.0)
    poses = np.stack([rig.pose(0.0, 0.0, 0.0)] * s.azimuth_steps) @ rig.mount((0, 0, H), (0, 0, 0))
    with Scanner(ground, s, threads=2, world=world) as sc:
        p = sc.scan(poses, t0=t0).points
    shown = set()
    for a in actors:
        on = p[p["instance"] == a.instance_id]
        assert len(on) > 100, a.name
        xyz = np.stack([on["x"], on["y"], on["z"], np.ones(len(on))], -1).astype(np.float64)
        w = np.einsum("kij,kj->ki", poses[on["column"]], xyz)[:, :3]
        tp = t0 + s.column_time()[on["column"]]
        T = a.track.pose(tp)
        local = np.einsum("kji,kj->ki", T[:, :3, :3], w - T[:, :3, 3])
        phase = a.gait.index(a.track, tp)
        for k in np.unique(phase):
            sel = phase == k
            assert _on_mesh(local[sel], protos[a.gait.keys[k]], 2e-3).all(), (a.name, k)
            other = protos[a.gait.keys[(k + 4) % len(a.gait.keys)]]
            assert not _on_mesh(local[sel], other, 2e-3).all(), (a.name, k)   # the limbs of another phase are elsewhere
            shown.add(int(k))
    assert len(shown) >= 2                                    # the sweep passed them at different phases


@pytest.mark.parametrize("threads", [1, 2])
def test_walkers_keep_bytes_identical_across_threads(threads):
    s = load_preset("hdl64e")
    ground = scene_of([("ground", rect(-60, -60, 60, 60, 0.0, "road", "asphalt"), 0)])
    protos: dict = {}
    actors = [walker(protos, straight((6.0 + i, -3.0 + 2 * i, 0.0), (0.3 * i, 1.3)), uid=i, instance_id=50 + i,
                     variant=i) for i in range(3)]
    world = World(ground, actors, protos, {}, None, 4.0)
    poses = np.stack([rig.pose(0.0, 0.0, 0.0)] * s.azimuth_steps) @ rig.mount((0, 0, H), (0, 0, 0))
    with Scanner(ground, s, threads=threads, world=world) as sc:
        a = sc.scan(poses, t0=1.0).points
    with Scanner(ground, s, threads=1, world=world) as sc:
        b = sc.scan(poses, t0=1.0).points
    assert a.tobytes() == b.tobytes()
    assert (np.isin(a["instance"], [50, 51, 52])).sum() > 300
