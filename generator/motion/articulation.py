"""A walker's limbs between two instants: surface points carried by the body and by their limb.

A walker shows one of its gait phase meshes at each instant (:class:`generator.world.actors.Gait`);
the meshes share their faces, so a surface point at ``t0`` -- on a triangle of the phase mesh shown
then, at barycentric coordinates ``(u, v, w)`` -- is at the same coordinates of the same triangle of
the mesh shown at ``t1``, moved by the body's rigid motion. Between two images 0.1 s apart the phase
advances about one or two of its sixteenth parts, so the limbs' own motion is part of the flow.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree
from trimesh.triangles import closest_point, points_to_barycentric

#: Triangles (by centroid distance) a point is tested against for its nearest triangle.
CANDIDATES = 24


def limb_displacement(m0, m1, local: np.ndarray) -> np.ndarray:
    """(n, 3) float64: how far each local point on ``m0`` moves with its triangle when ``m0`` becomes ``m1``.

    Parameters
    ----------
    m0, m1 : generator.geometry.Mesh
        The phase meshes at the two instants (same faces), the actor's local frame.
    local : (n, 3) float64
        Surface points at the first instant, local frame, metres.
    """
    local = np.asarray(local, np.float64).reshape(-1, 3)
    if len(local) == 0:
        return np.zeros((0, 3))
    tri0 = m0.vertices[m0.faces]
    k = min(CANDIDATES, len(tri0))
    _, cand = cKDTree(tri0.mean(1)).query(local, k=k)
    cand = cand.reshape(len(local), k)
    pts = np.repeat(local, k, 0)
    near = closest_point(tri0[cand.ravel()], pts)
    best = np.argmin(np.linalg.norm(near - pts, axis=1).reshape(-1, k), axis=1)
    face = cand[np.arange(len(local)), best]
    bary = points_to_barycentric(tri0[face], near.reshape(-1, k, 3)[np.arange(len(local)), best])
    move = (m1.vertices - m0.vertices)[m0.faces[face]]          # (n, 3 corners, 3)
    return np.einsum("nc,ncj->nj", bary, move)


def carry(mover, points_world: np.ndarray) -> np.ndarray:
    """(n, 3) float64: world points of ``mover``'s surface at ``t0`` where they are at ``t1``.

    Parameters
    ----------
    mover : generator.world.kinematics.Mover
        Its rigid motion, and its phase meshes when a walker's limbs moved (``mover.meshes``).
    points_world : (n, 3) float64
    """
    X = np.asarray(points_world, np.float64).reshape(-1, 3)
    T0, T1 = mover.T0, mover.T1
    local = (X - T0[:3, 3]) @ T0[:3, :3]
    if mover.meshes is not None:
        local = local + limb_displacement(*mover.meshes, local)
    return local @ T1[:3, :3].T + T1[:3, 3]
