"""Triangle meshes with per-face labels: the unit every asset builder returns.

A :class:`Mesh` carries, per triangle, the native class id (a tree has trunk and crown
faces) and the material id (from ``generator/materials.yaml``), plus named anchor points
(lamp positions, headlights) the renderer uses to place lights. The primitives that
build meshes are in :mod:`generator.geometry.primitives`; rigid transforms in
:mod:`generator.geometry.transforms`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from generator.geometry.transforms import apply, cross, pose

if TYPE_CHECKING:                   # trimesh (with scipy) costs ~0.7 s to import: only where used
    import trimesh


@dataclass
class Mesh:
    """A labelled triangle mesh in a local frame.

    Attributes
    ----------
    vertices : (n, 3) float64
        Local frame, metres, z up.
    faces : (m, 3) int64
        Vertex indices, counter-clockwise seen from outside (outward normals).
    face_class : (m,) uint8
        Native class id per triangle (``generator/labels/classes.yaml``).
    face_material : (m,) uint16
        Material id per triangle (``generator/materials.yaml``).
    anchors : dict of str to (k, 3) float64
        Named points in the local frame (e.g. ``"lamp"``, ``"headlight"``).
    """

    vertices: np.ndarray
    faces: np.ndarray
    face_class: np.ndarray
    face_material: np.ndarray
    anchors: dict[str, np.ndarray] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.vertices = np.asarray(self.vertices, np.float64).reshape(-1, 3)
        self.faces = np.asarray(self.faces, np.int64).reshape(-1, 3)
        m = len(self.faces)
        self.face_class = _per_face(self.face_class, np.uint8, m)
        self.face_material = _per_face(self.face_material, np.uint16, m)
        if self.anchors:
            self.anchors = {k: np.asarray(v, np.float64).reshape(-1, 3) for k, v in self.anchors.items()}
        else:
            self.anchors = {}

    @property
    def n_faces(self) -> int:
        return len(self.faces)

    def bounds(self) -> np.ndarray:
        """(2, 3) float64: min and max corner of the vertices."""
        if len(self.vertices) == 0:
            return np.zeros((2, 3))
        return np.stack([self.vertices.min(0), self.vertices.max(0)])

    def transformed(self, matrix: np.ndarray) -> Mesh:
        """A copy with vertices and anchors mapped by the 4x4 ``matrix``."""
        return Mesh(
            apply(matrix, self.vertices), self.faces, self.face_class, self.face_material,
            {k: apply(matrix, v) for k, v in self.anchors.items()},
        )

    def select(self, face_mask: np.ndarray) -> Mesh:
        """The sub-mesh of the faces where ``face_mask`` is True (unused vertices dropped)."""
        faces = self.faces[face_mask]
        used, inverse = np.unique(faces, return_inverse=True)
        return Mesh(self.vertices[used], inverse.reshape(-1, 3), self.face_class[face_mask],
                    self.face_material[face_mask], dict(self.anchors))

    def to_trimesh(self) -> trimesh.Trimesh:
        """A :class:`trimesh.Trimesh` of the geometry (labels not carried)."""
        import trimesh

        return trimesh.Trimesh(self.vertices, self.faces, process=False)


def _per_face(values, dtype, m: int) -> np.ndarray:
    """A fresh (m,) ``dtype`` array of ``values`` (one value per face, or one for all)."""
    a = np.asarray(values, dtype)
    if a.shape == (m,):
        return a.copy() if a is values else a      # a converted array is fresh already
    if a.ndim == 0:
        return np.full(m, a, dtype)
    return np.broadcast_to(a, (m,)).copy()


def empty() -> Mesh:
    """A mesh with no faces."""
    return Mesh(np.zeros((0, 3)), np.zeros((0, 3), np.int64), np.zeros(0, np.uint8), np.zeros(0, np.uint16))


def merge(meshes: list[Mesh]) -> Mesh:
    """Concatenate meshes (anchors with the same name are stacked)."""
    meshes = [m for m in meshes if m.n_faces or m.anchors]
    if not meshes:
        return empty()
    offsets = np.cumsum([0] + [len(m.vertices) for m in meshes[:-1]])
    anchors: dict[str, list[np.ndarray]] = {}
    for m in meshes:
        for k, v in m.anchors.items():
            anchors.setdefault(k, []).append(v)
    return Mesh(
        np.concatenate([m.vertices for m in meshes]),
        np.concatenate([m.faces + o for m, o in zip(meshes, offsets, strict=False)]),
        np.concatenate([m.face_class for m in meshes]),
        np.concatenate([m.face_material for m in meshes]),
        {k: np.concatenate(v) for k, v in anchors.items()},
    )


def on_ground(mesh: Mesh) -> Mesh:
    """The mesh shifted along z so that its lowest vertex is at z = 0 (anchors move with it)."""
    if len(mesh.vertices) == 0:
        return mesh
    return mesh.transformed(pose(z=-float(mesh.vertices[:, 2].min())))


def face_normals(mesh: Mesh) -> np.ndarray:
    """(m, 3) float64 unit normals of the faces (right-hand rule on the vertex order)."""
    tri = mesh.vertices[mesh.faces]
    n = cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    return n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
