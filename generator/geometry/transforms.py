"""Rigid transforms as (4, 4) float64 homogeneous matrices.

A transform ``T_a_b`` maps points in frame b to frame a. Angles in radians unless a name
says degrees; yaw is counter-clockwise seen from above (z up).
"""

from __future__ import annotations

import math

import numpy as np


def unit(v) -> np.ndarray:
    """Vectors ``v`` (..., 3) scaled to unit length along the last axis; a zero vector stays zero.

    Float input keeps its dtype (float32 stays float32); anything else becomes float64.
    """
    v = np.asarray(v)
    if v.dtype.kind != "f":
        v = v.astype(np.float64)
    # np.linalg.norm(v, axis=-1, keepdims=True) is sqrt(add.reduce(v * v, -1)) for real input: the
    # same operations, without its ~5 us of argument handling (people call this ~350 times each)
    return v / np.maximum(np.sqrt(np.add.reduce(v * v, axis=-1, keepdims=True)), 1e-12)


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``np.cross(a, b)`` for float64 (..., 3) vectors, the same products and differences in the same
    order (``a1 b2 - a2 b1``, ...), without np.cross's axis handling (~20 us a call)."""
    a, b = np.asarray(a), np.asarray(b)
    if a.shape[-1:] != (3,) or b.shape[-1:] != (3,):
        return np.cross(a, b)                   # 2-vectors and errors: numpy's own
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    out = np.empty(np.broadcast_shapes(a.shape, b.shape), np.result_type(a, b))
    out[..., 0] = a1 * b2 - a2 * b1
    out[..., 1] = a2 * b0 - a0 * b2
    out[..., 2] = a0 * b1 - a1 * b0
    return out


def apply(matrix: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Map (n, 3) points by a 4x4 homogeneous ``matrix``."""
    points = np.asarray(points, np.float64).reshape(-1, 3)
    return points @ matrix[:3, :3].T + matrix[:3, 3]


def pose(x: float = 0.0, y: float = 0.0, z: float = 0.0, yaw: float = 0.0,
         pitch: float = 0.0, roll: float = 0.0) -> np.ndarray:
    """4x4 float64 transform: rotate by roll (x), pitch (y), yaw (z), in that order, then translate.

    Angles in radians; yaw counter-clockwise seen from above.
    """
    cr, sr, cp, sp, cy, sy = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch), np.cos(yaw), np.sin(yaw)
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    m = np.eye(4)
    m[:3, :3] = rz @ ry @ rx
    m[:3, 3] = (x, y, z)
    return m



def invert(t: np.ndarray) -> np.ndarray:
    """Inverse of a rigid (4, 4) transform."""
    out = np.eye(4)
    out[:3, :3] = t[:3, :3].T
    out[:3, 3] = -t[:3, :3].T @ t[:3, 3]
    return out


def mount(xyz_m, rpy_deg) -> np.ndarray:
    """``T_parent_child`` of a body mounted at ``xyz_m`` (metres) with roll, pitch, yaw in degrees."""
    r, p, y = (math.radians(a) for a in rpy_deg)
    return pose(*xyz_m, yaw=y, pitch=p, roll=r)
