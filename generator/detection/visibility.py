"""How much of each boxed thing an image shows, from the passes already rendered.

For one image (camera pose and intrinsics at its exposure instant, its instance pass) and every
subject (:mod:`generator.detection.subjects`) whose own triangles project into it:

* **amodal** footprint: the subject's triangles at the exposure instant, clipped at the near plane,
  projected and rasterised alone (:mod:`generator.detection.raster`), sampled like the label pass;
* **visible** pixels: the instance pass's pixels holding one of the subject's instance ids;
* ``truncation``: the share of the amodal projection (unbounded by the image) outside the image;
* ``visibility``: visible pixels / amodal pixels inside the image (Synscapes' occlusion measure: the
  part hidden by other things, truncation kept apart as KITTI keeps them), in [0, 1];
* KITTI ``occlusion`` level: 0 fully visible (visibility >= 0.9, the slack for pixel edges), 1 partly
  occluded (>= 0.5), 2 largely occluded (> 0), 3 unknown (nothing visible: the image does not show it);
* KITTI ``difficulty`` from the devkit's limits on the 2D box height, occlusion and truncation
  (0 easy, 1 moderate, 2 hard, -1 none);
* nuScenes ``visibility`` token: "1" 0-40 %, "2" 40-60 %, "3" 60-80 %, "4" 80-100 % of the object visible.

2D boxes are ``(x0, y0, x1, y1)`` in pixels (corner coordinates, KITTI's ``bbox``): the amodal box is
the footprint's pixel extent inside the image, the visible box that of the visible pixels.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from generator.detection.frames import corners
from generator.detection.raster import NEAR_M, coverage_outside, footprint

#: KITTI difficulty limits: (2D box height above, max occlusion level, max truncation), devkit readme and
#: evaluate_object.cpp (a ground truth box of height <= the limit is ignored at that level).
KITTI_LEVELS = ((40.0, 0, 0.15), (25.0, 1, 0.30), (25.0, 2, 0.50))
#: Lower edges of the nuScenes visibility bins (tokens "1".."4").
NUSCENES_BINS = (0.0, 0.4, 0.6, 0.8)


@dataclass(frozen=True)
class ImageBox:
    """One subject in one image.

    Attributes
    ----------
    track_id : int
    bbox_amodal : (4,) float64
        ``(x0, y0, x1, y1)`` extent of the amodal footprint inside the image, pixels.
    bbox_visible : (4,) float64
        Extent of the visible pixels (zeros when none).
    pixels_amodal, pixels_visible : int
        Footprint pixels inside the image; pixels of the subject in the instance pass.
    truncation, visibility : float
        See the module docstring, [0, 1].
    occlusion : int
        KITTI occlusion level 0..3.
    difficulty : int
        KITTI difficulty 0 easy, 1 moderate, 2 hard, -1 none.
    nuscenes_visibility : str
        nuScenes visibility token "1".."4".
    """

    track_id: int
    bbox_amodal: np.ndarray
    bbox_visible: np.ndarray
    pixels_amodal: int
    pixels_visible: int
    truncation: float
    visibility: float
    occlusion: int
    difficulty: int
    nuscenes_visibility: str


def occlusion_level(visibility: float, pixels_visible: int) -> int:
    """KITTI occlusion level of a subject (module docstring)."""
    if pixels_visible <= 0:
        return 3
    return 0 if visibility >= 0.9 else 1 if visibility >= 0.5 else 2


def difficulty(height_px: float, occlusion: int, truncation: float) -> int:
    """KITTI difficulty (0 easy, 1 moderate, 2 hard, -1 none) of a 2D box height, occlusion level, truncation.

    As the devkit's evaluation counts them: a box of exactly the minimum height is too small.
    """
    for level, (h, occ, trunc) in enumerate(KITTI_LEVELS):
        if height_px > h and occlusion <= occ and truncation <= trunc:
            return level
    return -1


def nuscenes_bin(visibility: float) -> str:
    """nuScenes visibility token of a visible fraction."""
    return str(int(np.searchsorted(NUSCENES_BINS, visibility, side="right")))


def _extent(mask: np.ndarray, origin=(0, 0)) -> np.ndarray:
    rows, cols = np.flatnonzero(mask.any(1)), np.flatnonzero(mask.any(0))
    if not len(rows):
        return np.zeros(4)
    x, y = origin
    return np.array([x + cols[0], y + rows[0], x + cols[-1] + 1, y + rows[-1] + 1], np.float64)


def instance_extents(instance: np.ndarray) -> dict[int, tuple[int, np.ndarray]]:
    """Per instance id > 0 of an instance pass: (pixel count, (x0, y0, x1, y1) extent), in one pass."""
    h, w = instance.shape
    flat = instance.reshape(-1).astype(np.int64)
    ids, inv, counts = np.unique(flat, return_inverse=True, return_counts=True)
    rows, cols = np.divmod(np.arange(flat.size), w)
    ext = np.stack([np.full(len(ids), w), np.full(len(ids), h), np.zeros(len(ids), np.int64),
                    np.zeros(len(ids), np.int64)], 1)
    np.minimum.at(ext[:, 0], inv, cols)
    np.minimum.at(ext[:, 1], inv, rows)
    np.maximum.at(ext[:, 2], inv, cols + 1)
    np.maximum.at(ext[:, 3], inv, rows + 1)
    return {int(i): (int(c), e.astype(np.float64)) for i, c, e in zip(ids, counts, ext, strict=True) if i > 0}


def _union(extents) -> np.ndarray:
    if not extents:
        return np.zeros(4)
    e = np.array(extents)
    return np.r_[e[:, :2].min(0), e[:, 2:].max(0)]


def _may_show(subject, t: float, T_camera_world: np.ndarray, K: np.ndarray, width: int, height: int) -> bool:
    """Cheap test on the box corners: False only when the box cannot project into the image."""
    b = subject.box(t)
    c, s = np.cos(b.yaw), np.sin(b.yaw)
    R = T_camera_world[:3, :3] @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    p = corners(T_camera_world[:3, :3] @ np.asarray(b.center) + T_camera_world[:3, 3], b.size, R)
    if (p[:, 2] < NEAR_M).all():
        return False
    if (p[:, 2] < NEAR_M).any():
        return True  # crosses the camera plane: only the triangles can tell
    uv = (p @ K.T)[:, :2] / p[:, 2:3]
    return not (uv[:, 0].max() <= 0 or uv[:, 1].max() <= 0 or uv[:, 0].min() >= width or uv[:, 1].min() >= height)


def image_boxes(subjects, t: float, T_world_camera: np.ndarray, K: np.ndarray, instance: np.ndarray,
                supersample: int = 1) -> list[ImageBox]:
    """The visibility of every subject whose footprint touches one image.

    Parameters
    ----------
    subjects : list of generator.detection.subjects.Subject
    t : float
        Exposure instant, seconds on the world timeline (the instant of the label pass).
    T_world_camera : (4, 4) float64
        Camera (optical frame: x right, y down, z forward) pose in the world at ``t``.
    K : (3, 3) float64
        Intrinsics of the image.
    instance : (H, W) integer
        The image's instance pass.
    supersample : int
        The render config's ``label_supersample`` (the footprint is sampled like the label pass).

    Returns
    -------
    list of ImageBox
        Subjects with at least one footprint pixel inside the image, by ``track_id``.
    """
    height, width = instance.shape
    T_cw = np.linalg.inv(np.asarray(T_world_camera, np.float64))
    K = np.asarray(K, np.float64)
    seen = instance_extents(instance)
    out = []
    for s in subjects:
        if not _may_show(s, t, T_cw, K, width, height):
            continue
        v, f = s.triangles(t)
        tri = (v @ T_cw[:3, :3].T + T_cw[:3, 3])[f]
        amodal, origin = footprint(tri, K, width, height, supersample)
        n_amodal = int(amodal.sum())
        if n_amodal == 0:
            continue
        parts = [seen[i] for i in s.instance_ids if i in seen]
        n_vis = sum(c for c, _ in parts)
        trunc = coverage_outside(tri, K, width, height)
        visibility = min(1.0, n_vis / n_amodal)
        box = _extent(amodal, origin)
        occ = occlusion_level(visibility, n_vis)
        out.append(ImageBox(s.track_id, box, _union([e for _, e in parts]), n_amodal, n_vis, trunc, visibility, occ,
                            difficulty(box[3] - box[1], occ, trunc), nuscenes_bin(visibility)))
    return out
