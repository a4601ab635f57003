"""Tiny hand-made SceneModels for tests (no layout needed)."""

from __future__ import annotations

import numpy as np

from generator import geometry as M
from generator.labels import class_table
from generator.world.scene import OrientedBox, Path, SceneModel, SceneObject


def make_scene(parts, seed: int = 0, paths=None, proxies=None) -> SceneModel:
    """Wrap meshes into a SceneModel.

    Parameters
    ----------
    parts : list of (name, Mesh, (4, 4) transform, instance_id)
        One object per entry; the mesh becomes its own prototype.
    proxies : dict of name -> Mesh, optional
        Label proxies (same local frame as the named part).
    """
    protos, objs, proxies = {}, [], dict(proxies or {})
    for i, (name, mesh, t, inst) in enumerate(parts):
        protos[name] = mesh
        v = M.apply(t, mesh.vertices)
        lo, hi = v.min(0), v.max(0)
        cls = class_table()[int(np.bincount(mesh.face_class).argmax())].name
        objs.append(SceneObject(i, name, "test", cls, inst, name, t,
                                OrientedBox(tuple((lo + hi) / 2), tuple(hi - lo), 0.0),
                                name if name in proxies else None))
    if paths is None:
        xs = np.arange(0.0, 50.0, 1.0)
        pts = np.c_[xs, np.zeros_like(xs), np.zeros_like(xs)]
        paths = [Path("straight", pts, np.zeros_like(xs), xs.copy(), False)]
    allv = np.concatenate([M.apply(t, m.vertices) for _, m, t, _ in parts])
    bounds = np.stack([allv.min(0)[:2], allv.max(0)[:2]])
    return SceneModel(seed, "test", bounds, protos, proxies, objs, paths)


def fence_scene() -> SceneModel:
    """Ground, a building wall 12 m ahead (+x) and a bar fence 6 m ahead with its hull proxy."""
    ground = M.rect(-50, -50, 50, 50, 0.0, "road", "asphalt")
    wall = M.box((1.0, 30.0, 10.0), "building", "facade_brick", center=(0, 0, 5.0))
    bars = [M.box((0.05, 0.05, 1.6), "fence", "fence_metal", center=(0, y, 0.8)) for y in np.arange(-4, 4.01, 0.25)]
    rails = [M.box((0.05, 8.1, 0.05), "fence", "fence_metal", center=(0, 0, z)) for z in (0.1, 1.55)]
    fence = M.merge(bars + rails)
    hull = M.convex_hull(fence, "fence")
    return make_scene([
        ("ground", ground, np.eye(4), 0),
        ("wall", wall, M.pose(12.5, 0, 0), 1),
        ("fence", fence, M.pose(6.0, 0, 0), 2),
    ], proxies={"fence": hull})
