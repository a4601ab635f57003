"""Whether points lie on a mesh's triangles (plane distance and barycentric inside), for LiDAR tests."""

from __future__ import annotations

import numpy as np


def on_surface(points, vertices, faces, tol):
    """(n,) bool: each point lies within ``tol`` of the plane of a triangle and inside it (barycentric)."""
    a, b, c = (vertices[faces[:, i]] for i in range(3))
    n = np.cross(b - a, c - a)
    area2 = np.linalg.norm(n, axis=1)
    keep = area2 > 1e-12
    a, b, c, n, area2 = a[keep], b[keep], c[keep], n[keep] / area2[keep, None], area2[keep]
    out = np.zeros(len(points), bool)
    for i, p in enumerate(points):
        near = np.abs(((p - a) * n).sum(1)) < tol
        q = p - ((p - a[near]) * n[near]).sum(1)[:, None] * n[near]  # projection onto each plane
        w = [(np.cross(v1 - q, v2 - q) * n[near]).sum(1) / area2[near]
             for v1, v2 in ((b[near], c[near]), (c[near], a[near]), (a[near], b[near]))]
        out[i] = len(q) > 0 and np.any(np.min(w, axis=0) > -tol)
    return out
