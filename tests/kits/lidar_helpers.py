"""Tiny SceneModels for the LiDAR tests: meshes wrapped as objects, plus a straight route."""

from __future__ import annotations

import numpy as np

from generator.geometry import Mesh
from generator.world.scene import OrientedBox, Path, SceneModel, SceneObject


def straight_path(x0: float = -200.0, x1: float = 200.0, y: float = 0.0, heading: float = 0.0,
                  name: str = "route_0") -> Path:
    """A route along +x (or rotated by ``heading``) through (0, y), samples 1 m apart."""
    s = np.arange(0.0, x1 - x0 + 1e-9, 1.0)
    d = np.array([np.cos(heading), np.sin(heading), 0.0])
    start = np.array([0.0, y, 0.0]) + x0 * d
    pts = start + s[:, None] * d
    return Path(name, pts, np.full(len(s), heading), s, closed=False)


def scene_of(meshes: list[tuple[str, Mesh, int]], paths: list[Path] | None = None, seed: int = 0) -> SceneModel:
    """Wrap ``(name, mesh, instance_id)`` triples (world-frame meshes) into a SceneModel."""
    objects, protos = [], {}
    for i, (name, mesh, inst) in enumerate(meshes):
        lo, hi = mesh.bounds()
        box = OrientedBox(tuple((lo + hi) / 2), tuple(np.maximum(hi - lo, 1e-3)), 0.0)
        from generator.labels import class_table
        cls = class_table().names[int(np.bincount(mesh.face_class).argmax())]
        objects.append(SceneObject(i, name, name, cls, inst, name, np.eye(4), box))
        protos[name] = mesh
    allv = np.concatenate([m.vertices for _, m, _ in meshes])
    bounds = np.array([allv[:, :2].min(0), allv[:, :2].max(0)])
    return SceneModel(seed, "test", bounds, protos, {}, objects, paths or [straight_path()])
