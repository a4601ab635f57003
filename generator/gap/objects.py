"""Objects of a scan and how many of its points each holds: from 3D boxes, or from instance labels.

Boxes are read through this one adapter (:func:`box_reader`), so a change of box records (the detection
work extends them) touches only here. Today's source is urbangen's OpenLABEL file
``openlabel/NN.json`` beside the SemanticKITTI root or one folder up (a ``generate`` dataset keeps
``lidar/`` and ``openlabel/`` side by side), read by :class:`generator.dataset.Dataset`: cuboids in the
ego frame of their sweep, turned into the LiDAR frame with the mount of ``lidar_meta.json``. A box's
points are the scan's points inside it, counted here rather than taken from the record: a processed
copy of a scan (seed 002's dropout) keeps its boxes but not its counts.

Without boxes, an object is a thing instance of the labels (:func:`instance_objects`; SemanticKITTI has
them: car, bicycle, motorcycle, truck, other-vehicle, person, bicyclist, motorcyclist), its distance the
centroid's.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generator.labels.sets import label_sets

#: SemanticKITTI learning classes that are things (instances): car .. motorcyclist.
THING_CLASSES = ("car", "bicycle", "motorcycle", "truck", "other-vehicle", "person", "bicyclist", "motorcyclist")


@dataclass
class ObjectCounts:
    """Objects of one scan.

    Attributes
    ----------
    cls : list of str
        Class of each object (box type, or learning-class name).
    distance_m : (k,) float64
        Distance of its centre from the sensor, metres.
    points : (k,) int64
        Scan points on it.
    """

    cls: list
    distance_m: np.ndarray
    points: np.ndarray


class BoxReader:
    """The cuboids of one sequence, as point counts of a scan (see the module docstring)."""

    def __init__(self, dataset, T_ego_lidar: np.ndarray):
        self.dataset = dataset
        self.T_ego_lidar = T_ego_lidar

    def __call__(self, index: int, xyz: np.ndarray) -> ObjectCounts:
        """Objects of sweep ``index`` with the points of ``xyz`` (n, 3) (LiDAR frame) inside each box."""
        boxes = self.dataset.boxes(index)
        if not boxes:
            return ObjectCounts([], np.zeros(0), np.zeros(0, np.int64))
        p = np.asarray(xyz, np.float64) @ self.T_ego_lidar[:3, :3].T + self.T_ego_lidar[:3, 3]  # ego frame
        lidar_origin = self.T_ego_lidar[:3, 3]
        centres = np.array([b.center for b in boxes], np.float64)
        halves = np.array([b.size for b in boxes], np.float64) / 2
        order = np.argsort(p[:, 0], kind="stable")
        xs, p = p[order, 0], p[order]
        reach = np.linalg.norm(halves, axis=1)
        lo = np.searchsorted(xs, centres[:, 0] - reach)
        hi = np.searchsorted(xs, centres[:, 0] + reach, side="right")
        counts, dist = [], []
        for b, c, half, r, i, j in zip(boxes, centres, halves, reach, lo, hi, strict=True):
            near = p[i:j]
            near = near[np.abs(near[:, 1] - c[1]) <= r]
            q = np.asarray(b.quaternion, np.float64)
            local = (near - c) @ _rotation(q / np.linalg.norm(q))  # box frame
            counts.append(int(np.all(np.abs(local) <= half, axis=1).sum()))
            dist.append(float(np.linalg.norm(c - lidar_origin)))
        return ObjectCounts([b.cls for b in boxes], np.array(dist), np.array(counts, np.int64))


def _rotation(q: np.ndarray) -> np.ndarray:
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def box_reader(root: Path, sequence: str) -> BoxReader | None:
    """The boxes of ``root``'s sequence, or None when there are none (see the module docstring)."""
    from generator.dataset import Dataset
    from generator.geometry.transforms import mount
    from generator.imaging.meta_fields import load_metadata, matrix

    for folder in (root, root.parent):
        if os.path.lexists(folder / "openlabel" / f"{sequence}.json"):
            meta = root / "sequences" / sequence / "lidar_meta.json"
            if not os.path.lexists(meta):
                return None
            doc = load_metadata(meta)
            T = mount(matrix(doc, "mount.lidar_xyz_m", (3,), str(meta)),
                      matrix(doc, "mount.lidar_rpy_deg", (3,), str(meta)))
            return BoxReader(Dataset(folder, sequence), T)
    return None


def instance_objects(xyz: np.ndarray, learning: np.ndarray, instance: np.ndarray) -> ObjectCounts:
    """One object per (thing class, instance id > 0) of a labelled scan."""
    ls = label_sets()["semantickitti"]
    things = np.array([n in THING_CLASSES for n in ls.names])
    on = things[learning] & (instance > 0)
    if not on.any():
        return ObjectCounts([], np.zeros(0), np.zeros(0, np.int64))
    key = learning[on] * (1 << 32) + instance[on]
    uniq, inv, count = np.unique(key, return_inverse=True, return_counts=True)
    centre = np.stack([np.bincount(inv, np.asarray(xyz, np.float64)[on, i]) for i in range(3)], -1) / count[:, None]
    return ObjectCounts([ls.names[int(k >> 32)] for k in uniq], np.linalg.norm(centre, axis=1), count.astype(np.int64))
