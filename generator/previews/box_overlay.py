"""Boxes drawn over an image: 3D box edges, amodal and visible 2D boxes, coloured by KITTI occlusion level.

For a person checking labels by eye: green fully visible (0), yellow partly occluded (1), orange largely
occluded (2), red not visible in the image (3). The 3D box is drawn with its edges clipped at the near
plane; the amodal 2D box is a thin outline, the visible one a thick outline.
"""

from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw

#: KITTI occlusion level -> RGB
OCCLUSION_COLOURS = {0: (40, 220, 60), 1: (250, 220, 30), 2: (255, 130, 20), 3: (230, 30, 30)}
#: The 12 edges of a box, corner indices in KITTI order (bottom face 0-3, top face 4-7).
EDGES = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7)]
NEAR_M = 0.1


def _segment(p, q, K, near=NEAR_M):
    """The pixel segment of camera-frame edge p-q clipped at ``z = near`` (None if wholly behind)."""
    if p[2] < near and q[2] < near:
        return None
    if p[2] < near or q[2] < near:
        s = (near - p[2]) / (q[2] - p[2])
        cut = p + s * (q - p)
        p, q = (cut, q) if p[2] < near else (p, cut)
    a, b = K @ p, K @ q
    return (float(a[0] / a[2]), float(a[1] / a[2])), (float(b[0] / b[2]), float(b[1] / b[2]))


def draw_boxes(rgb: np.ndarray, K: np.ndarray, boxes, scale: int = 1) -> Image.Image:
    """An RGB image with its boxes.

    Parameters
    ----------
    rgb : (H, W, 3) uint8
    K : (3, 3) float64
        Intrinsics of the image.
    boxes : iterable of (corners, bbox_amodal, bbox_visible, occlusion)
        ``corners`` (8, 3) camera frame (optical), metres, KITTI corner order; 2D boxes ``(x0, y0, x1, y1)``
        in pixels (corner coordinates); ``occlusion`` the KITTI level.
    scale : int
        Upscale factor of the picture (small renders), lines stay thin.
    """
    img = Image.fromarray(np.asarray(rgb, np.uint8)).resize((rgb.shape[1] * scale, rgb.shape[0] * scale),
                                                            Image.NEAREST)
    d = ImageDraw.Draw(img)
    for corners, amodal, visible, occ in boxes:
        colour = OCCLUSION_COLOURS.get(int(occ), (255, 255, 255))
        for i, j in EDGES:
            seg = _segment(np.asarray(corners[i], float), np.asarray(corners[j], float), K)
            if seg is not None:
                d.line([(x * scale, y * scale) for x, y in seg], fill=colour, width=1)
        x0, y0, x1, y1 = (float(v) * scale for v in amodal)
        d.rectangle([x0, y0, x1 - 1, y1 - 1], outline=colour, width=1)
        if visible is not None and np.any(np.asarray(visible) > 0):
            x0, y0, x1, y1 = (float(v) * scale for v in visible)
            d.rectangle([x0, y0, x1 - 1, y1 - 1], outline=colour, width=max(2, scale))
    return img
