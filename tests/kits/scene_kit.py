"""Tiny hand-made SceneModels for tests (no layout needed): meshes wrapped as objects, plus a route."""

from __future__ import annotations

import numpy as np

from generator import geometry as M
from generator.labels import class_table
from generator.world.scene import OrientedBox, Path, SceneModel, SceneObject


def straight_path(x0: float = -200.0, x1: float = 200.0, y: float = 0.0, heading: float = 0.0,
                  name: str = "route_0") -> Path:
    """A route along +x (or rotated by ``heading``) through (0, y), samples 1 m apart."""
    s = np.arange(0.0, x1 - x0 + 1e-9, 1.0)
    d = np.array([np.cos(heading), np.sin(heading), 0.0])
    start = np.array([0.0, y, 0.0]) + x0 * d
    pts = start + s[:, None] * d
    return Path(name, pts, np.full(len(s), heading), s, closed=False)


def make_scene(parts, seed: int = 0, paths=None, proxies=None, kind: str | None = "test") -> SceneModel:
    """Wrap meshes into a SceneModel.

    Parameters
    ----------
    parts : list of (name, Mesh, (4, 4) transform, instance_id)
        One object per entry; the mesh becomes its own prototype, its class the class most of
        its faces carry, its box the axis-aligned bounds of the placed mesh (at least 1 mm a side).
    paths : list of Path, optional
        Default: one straight route from (0, 0) to (49, 0) named ``straight``.
    proxies : dict of name -> Mesh, optional
        Label proxies (same local frame as the named part).
    kind : str or None
        Every object's kind; None: each object's name.
    """
    protos, objs, proxies = {}, [], dict(proxies or {})
    for i, (name, mesh, t, inst) in enumerate(parts):
        protos[name] = mesh
        v = M.apply(t, mesh.vertices)
        lo, hi = v.min(0), v.max(0)
        cls = class_table()[int(np.bincount(mesh.face_class).argmax())].name
        objs.append(SceneObject(i, name, name if kind is None else kind, cls, inst, name, t,
                                OrientedBox(tuple((lo + hi) / 2), tuple(np.maximum(hi - lo, 1e-3)), 0.0),
                                name if name in proxies else None))
    if paths is None:
        xs = np.arange(0.0, 50.0, 1.0)
        pts = np.c_[xs, np.zeros_like(xs), np.zeros_like(xs)]
        paths = [Path("straight", pts, np.zeros_like(xs), xs.copy(), False)]
    allv = np.concatenate([M.apply(t, m.vertices) for _, m, t, _ in parts])
    bounds = np.stack([allv.min(0)[:2], allv.max(0)[:2]])
    return SceneModel(seed, "test", bounds, protos, proxies, objs, paths)


def scene_of(meshes, paths: list[Path] | None = None, seed: int = 0) -> SceneModel:
    """:func:`make_scene` of ``(name, mesh, instance_id)`` triples already in the world frame, each
    object of its own kind (its name), driven along :func:`straight_path` unless ``paths`` say."""
    return make_scene([(name, mesh, np.eye(4), inst) for name, mesh, inst in meshes], seed,
                      paths or [straight_path()], kind=None)


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
