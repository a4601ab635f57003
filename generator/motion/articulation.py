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


def limb_flows(walkers: dict, prototypes: dict, lookup: np.ndarray, times: np.ndarray, dt: float,
               T_world_lidar: np.ndarray, xyz: np.ndarray, column: np.ndarray, instance: np.ndarray, rows: np.ndarray,
               E: np.ndarray, obj: np.ndarray, moved: np.ndarray) -> None:
    """Add the walkers' limb motion to their LiDAR points' scene flows, in place
    (:class:`generator.motion.scene_flow.SceneFlow`): each point moves with its triangle of the gait phase mesh
    shown at its firing instant to the same triangle of the one shown ``dt`` later.

    Parameters
    ----------
    walkers : dict of int to Actor
        Index into the flow's actors -> a walker (``actor.gait`` set).
    prototypes : dict of str to Mesh
        The world's prototypes (the phase meshes).
    lookup : (max_id + 1,) int64
        Instance id -> index into the flow's actors (-1 elsewhere).
    times : (steps,) float64
        Firing instant of each column, seconds.
    dt : float
        Time to the next sweep's column, seconds.
    T_world_lidar : (steps, 4, 4) float64
        The LiDAR's pose at each column's instant.
    xyz : (3, n) float32
        Points, LiDAR frame at their firing instant.
    column, instance : (n,) integer
    rows : (m,) int64
        Points on actors.
    E : (steps, 3, 4) float64
        LiDAR frame at a column's instant -> the LiDAR frame ``dt`` later.
    obj : (n, 3) float32
        Object flows (LiDAR axes at the firing instant), updated.
    moved : (3, n) float32
        Points moved (``x + ego``), updated.
    """
    who = lookup[instance[rows].astype(np.int64)]
    for i, a in walkers.items():
        mine = rows[who == i]
        if len(mine) == 0:
            continue
        col = column[mine].astype(np.int64)
        t = times[col]
        k0, k1 = a.gait.index(a.track, t), a.gait.index(a.track, t + dt)
        Tc, A0, A1 = T_world_lidar[col], a.track.pose(t), a.track.pose(t + dt)
        X = np.einsum("kij,kj->ki", Tc[:, :3, :3], xyz[:, mine].T.astype(np.float64)) + Tc[:, :3, 3]
        local = np.einsum("kji,kj->ki", A0[:, :3, :3], X - A0[:, :3, 3])
        d = np.zeros_like(local)
        for p0, p1 in set(zip(k0.tolist(), k1.tolist(), strict=True)):
            if p0 != p1:
                sel = (k0 == p0) & (k1 == p1)
                d[sel] = limb_displacement(prototypes[a.gait.keys[p0]], prototypes[a.gait.keys[p1]], local[sel])
        step = np.einsum("kji,kj->ki", Tc[:, :3, :3], np.einsum("kij,kj->ki", A1[:, :3, :3], d))  # LiDAR axes
        obj[mine] += step.astype(np.float32)
        moved[:, mine] += np.einsum("kij,kj->ki", E[col, :, :3], step).T.astype(np.float32)
