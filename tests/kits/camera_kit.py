"""Camera poses for Blender tests."""

from __future__ import annotations

import numpy as np


def look_at(eye, target) -> np.ndarray:
    """(4, 4) world-from-camera pose at ``eye`` looking at ``target`` (camera z forward, x right, world z up)."""
    eye, target = np.asarray(eye, float), np.asarray(target, float)
    z = (target - eye) / np.linalg.norm(target - eye)
    x = np.cross(z, [0.0, 0.0, 1.0])
    x /= np.linalg.norm(x)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, np.cross(z, x), z, eye
    return T
