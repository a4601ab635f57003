"""Face index arrays the primitives share: they depend only on a mesh's shape (section counts, ring
counts), so each is made once per shape and handed out read-only (callers copy what they keep).

A town makes ~3000 cylinders, ~2500 polygons and hundreds of lofts of a handful of shapes; building
their faces afresh each time cost more than their vertices.
"""

from __future__ import annotations

import functools

import numpy as np


@functools.lru_cache(maxsize=64)
def cylinder_parts(sections: int, caps: bool) -> tuple[np.ndarray, np.ndarray]:
    """The unit ring (cos, sin) and the faces of :func:`generator.geometry.primitives.cylinder`
    (read-only)."""
    a = np.linspace(0, 2 * np.pi, sections, endpoint=False)
    ring = np.stack([np.cos(a), np.sin(a)], 1)
    i = np.arange(sections)
    j = (i + 1) % sections
    faces = [np.stack([i, j, j + sections], 1), np.stack([i, j + sections, i + sections], 1)]
    if caps:
        cb, ct = 2 * sections, 2 * sections + 1
        faces += [
            np.stack([np.full(sections, cb), j, i], 1),
            np.stack([np.full(sections, ct), i + sections, j + sections], 1),
        ]
    faces = np.concatenate(faces)
    ring.setflags(write=False)
    faces.setflags(write=False)
    return ring, faces


@functools.lru_cache(maxsize=256)
def loft_faces(s: int, k: int) -> np.ndarray:
    """The side faces of :func:`generator.geometry.primitives.loft` for ``s`` rings of ``k`` points
    (read-only), before they are oriented."""
    i = np.arange(k)
    j = (i + 1) % k
    faces = []
    for r in range(s - 1):
        a, b = r * k + i, (r + 1) * k + i
        an, bn = r * k + j, (r + 1) * k + j
        faces += [np.stack([a, an, bn], 1), np.stack([a, bn, b], 1)]
    out = np.concatenate(faces)
    out.setflags(write=False)
    return out


@functools.lru_cache(maxsize=256)
def fan_faces(k: int) -> np.ndarray:
    """The fan faces of :func:`generator.geometry.primitives.polygon` for ``k`` points (read-only)."""
    out = np.stack([np.zeros(k - 2, np.int64), np.arange(1, k - 1), np.arange(2, k)], 1)
    out.setflags(write=False)
    return out
