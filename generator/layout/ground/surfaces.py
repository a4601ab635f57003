"""The pieces every ground mesh is made of: flat rectangles, dash patterns, kerb slabs (metres)."""

from __future__ import annotations

import numpy as np

from generator.geometry import Mesh, slab
from generator.labels import class_table
from generator.materials import material_table

DASH_M, GAP_M = 3.0, 6.0   #: centre-line dash pattern


def rects(boxes: np.ndarray, z: float, cls: str, material: str) -> Mesh:
    """Many flat upward-facing rectangles at height ``z`` in one mesh.

    Parameters
    ----------
    boxes : (k, 4) float
        ``(x0, y0, x1, y1)`` per rectangle (any corner order), metres.
    """
    b = np.asarray(boxes, np.float64).reshape(-1, 4)
    x0, x1 = np.minimum(b[:, 0], b[:, 2]), np.maximum(b[:, 0], b[:, 2])
    y0, y1 = np.minimum(b[:, 1], b[:, 3]), np.maximum(b[:, 1], b[:, 3])
    keep = (x1 - x0 > 1e-6) & (y1 - y0 > 1e-6)
    x0, x1, y0, y1 = x0[keep], x1[keep], y0[keep], y1[keep]
    k = len(x0)
    zz = np.full(k, z)
    v = np.stack([np.stack([x0, y0, zz], 1), np.stack([x1, y0, zz], 1),
                  np.stack([x1, y1, zz], 1), np.stack([x0, y1, zz], 1)], 1).reshape(-1, 3)
    base = (np.arange(k) * 4)[:, None]
    f = np.concatenate([base + [0, 1, 2], base + [0, 2, 3]], 1).reshape(-1, 3)
    return Mesh(v, f, class_table().id(cls), material_table().id(material))


def dashes(a0: float, a1: float, v0: float, v1: float, dash: float = DASH_M, gap: float = GAP_M) -> np.ndarray:
    """(k, 4) ``(u0, v0, u1, v1)`` dash rectangles along ``[a0, a1]`` between ``v0`` and ``v1`` (metres)."""
    starts = np.arange(a0, a1, dash + gap)
    return np.stack([starts, np.full_like(starts, v0), np.minimum(starts + dash, a1), np.full_like(starts, v1)], 1)


def curb(x0: float, y0: float, x1: float, y1: float, h: float) -> Mesh:
    """A kerb slab (class curb) over the rectangle (x0, y0)..(x1, y1) from the road (z = 0) up to ``h``."""
    return slab(min(x0, x1), min(y0, y1), max(x0, x1), max(y0, y1), 0.0, h, "curb", "curb_concrete")
