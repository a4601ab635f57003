"""3D semantic map of a sequence (seed 001 Eq. 2): labelled points in one frame, voxelised.

Eq. 2 of seed 001: ``point_pose = pose @ point_LiDAR``. Each scan's (de-skewed) points go
into the frame of the FIRST LiDAR scan with the scan's LiDAR pose (``poses.txt`` read the
SemanticKITTI way, ``inv(Tr) @ pose @ Tr``), and are counted into voxels: every voxel keeps
its point count, the centroid of its points and the majority label (ties -> the lower class
id). Counting is incremental (one ``np.unique`` per scan plus a merge), so a long sequence
never holds all its points at once.

Labels are native class ids, coloured with the Cityscapes colours of the class table. A
SemanticKITTI-only dataset gives raw ids; their canonical native class
(``class_table().from_semantickitti``) is many-to-one lossy: lane-marking 60 comes from both
road_marking and crosswalk, sidewalk 48 from sidewalk and curb, vegetation 70 from
vegetation and tree_crown, traffic-sign 81 from traffic_light and traffic_sign. urbangen
sequences carry ``native_labels/`` side files, so their maps keep every native class.

Only the STATIC world is accumulated (:meth:`VoxelMap.add_static`): points labelled moving-*
(SemanticKITTI raw ids 252-259) and every point of an actor (its instance id; a car waiting at a
light is static in its label but still a mover) are left out, so a car driving through the
sequence leaves no smear of voxels along its path. The dropped points are what dynamic-object
removal research wants separated; :func:`generator.fusion.movers.static_mask` says which.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from generator.atomic import atomic_path, write_bytes
from generator.errors import UserError
from generator.labels import class_table

LABEL_BITS = 6  # native ids < 64 (the class table has 34)
AXIS_BITS = 19  # 3 * 19 + 6 = 63 bits: +-262k voxels per axis, keys stay positive int64
_OFFSET = 1 << (AXIS_BITS - 1)
#: Voxel edges accepted, metres.
MIN_VOXEL_M, MAX_VOXEL_M = 0.001, 1000.0


class VoxelMap:
    """Voxel counts per (voxel, label), accumulated scan by scan.

    Parameters
    ----------
    voxel_m : float
        Voxel edge, metres.

    Raises
    ------
    UserError
        A voxel edge that is not a finite number in [:data:`MIN_VOXEL_M`, :data:`MAX_VOXEL_M`]
        (it comes from the command line's ``--voxel``).
    """

    def __init__(self, voxel_m: float = 0.2):
        try:
            v = float(voxel_m)
        except (TypeError, ValueError):
            v = math.nan
        if not (math.isfinite(v) and MIN_VOXEL_M <= v <= MAX_VOXEL_M):
            raise UserError(f"--voxel: the voxel edge must be a finite number in [{MIN_VOXEL_M}, {MAX_VOXEL_M}] m, "
                            f"got {voxel_m}")
        self.voxel_m = v
        self._key = np.zeros(0, np.int64)  # voxel << LABEL_BITS | label
        self._count = np.zeros(0, np.int64)
        self._sum = np.zeros((0, 3), np.float64)
        self.points = 0
        self.dropped = 0  # moving / actor points left out by add_static

    def add(self, xyz: np.ndarray, labels: np.ndarray) -> None:
        """Count (n, 3) float points (map frame, metres) with (n,) native labels (< 64)."""
        xyz = np.asarray(xyz, np.float64).reshape(-1, 3)
        labels = np.asarray(labels, np.int64)
        if labels.size and (labels.min() < 0 or labels.max() >= 1 << LABEL_BITS):
            raise ValueError(f"labels must be in 0..{(1 << LABEL_BITS) - 1}")
        reach = (_OFFSET - 1) * self.voxel_m
        if xyz.size and not (np.isfinite(xyz).all() and np.abs(xyz).max() < reach):
            raise UserError(f"semantic map: points farther than {reach:.0f} m from the first scan "
                            "(poses.txt, calib.txt or the scans hold far-off values; or choose a larger --voxel)")
        idx = np.floor(xyz / self.voxel_m).astype(np.int64) + _OFFSET
        key = (((idx[:, 0] << AXIS_BITS | idx[:, 1]) << AXIS_BITS | idx[:, 2]) << LABEL_BITS) | labels
        self._merge(key, np.ones(len(key), np.int64), xyz)
        self.points += len(key)

    def add_static(self, xyz: np.ndarray, labels: np.ndarray, semantic: np.ndarray, instance: np.ndarray,
                   actor_instances=()) -> int:
        """Count only the static points of a scan; returns how many points were dropped.

        Parameters
        ----------
        xyz : (n, 3) float
            Map frame, metres.
        labels : (n,) integer
            Native classes (< 64).
        semantic, instance : (n,) integer
            SemanticKITTI raw id and instance id per point (moving-* ids 252-259 are dropped).
        actor_instances : iterable of int
            Instance ids of the actors (dropped whatever their label).
        """
        from generator.fusion.movers import static_mask

        keep = static_mask(semantic, instance, actor_instances)
        self.add(np.asarray(xyz, np.float64).reshape(-1, 3)[keep], np.asarray(labels)[keep])
        self.dropped += int((~keep).sum())
        return int((~keep).sum())

    def _merge(self, key: np.ndarray, count: np.ndarray, sums: np.ndarray) -> None:
        key = np.concatenate([self._key, key])
        uniq, inv = np.unique(key, return_inverse=True)
        self._count = np.bincount(inv, np.concatenate([self._count, count]), len(uniq)).astype(np.int64)
        allsum = np.concatenate([self._sum, sums])
        self._sum = np.stack([np.bincount(inv, allsum[:, i], len(uniq)) for i in range(3)], -1)
        self._key = uniq

    def voxels(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The downsampled map.

        Returns
        -------
        xyz : (v, 3) float64
            Centroid of each voxel's points, metres.
        label : (v,) uint8
            Majority native label.
        count : (v,) int64
            Points in the voxel.
        """
        vox = self._key >> LABEL_BITS
        lab = self._key & ((1 << LABEL_BITS) - 1)
        uniq, inv = np.unique(vox, return_inverse=True)
        total = np.bincount(inv, self._count, len(uniq))
        sums = np.stack([np.bincount(inv, self._sum[:, i], len(uniq)) for i in range(3)], -1)
        order = np.lexsort((-lab, self._count, inv))  # per voxel: count ascending, then lower label last
        last = np.r_[inv[order][1:] != inv[order][:-1], True]
        label = np.empty(len(uniq), np.uint8)
        label[inv[order][last]] = lab[order][last]
        return sums / total[:, None], label, total.astype(np.int64)


MAP_PLY_DTYPE = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("count", "<u4"), ("semantic", "<u2"),
                          ("native", "u1"), ("red", "u1"), ("green", "u1"), ("blue", "u1")])
_PLY_TYPES = {"<f4": "float", "<u4": "uint", "<u2": "ushort", "|u1": "uchar"}


def write_map_ply(path: str | Path, xyz: np.ndarray, label: np.ndarray, count: np.ndarray,
                  comment: str = "urbangen semantic map") -> None:
    """Binary PLY of the voxel map: x, y, z (map frame, m), points per voxel, SemanticKITTI raw id,
    native class, Cityscapes RGB of the class."""
    t = class_table()
    v = np.empty(len(xyz), MAP_PLY_DTYPE)
    v["x"], v["y"], v["z"] = xyz[:, 0], xyz[:, 1], xyz[:, 2]
    v["count"] = np.minimum(count, np.iinfo(np.uint32).max)
    v["semantic"] = t.to_semantickitti[label]
    v["native"] = label
    rgb = t.colors[label]
    v["red"], v["green"], v["blue"] = rgb[:, 0], rgb[:, 1], rgb[:, 2]
    header = ["ply", "format binary_little_endian 1.0", f"comment {comment}", f"element vertex {len(v)}"]
    header += [f"property {_PLY_TYPES[MAP_PLY_DTYPE[n].str]} {n}" for n in MAP_PLY_DTYPE.names]
    header.append("end_header")
    write_bytes(path, ("\n".join(header) + "\n").encode("ascii") + v.tobytes())


def _font(size: int) -> ImageFont.ImageFont:
    try:
        return ImageFont.load_default(size=size)
    except TypeError:  # pragma: no cover - old Pillow
        return ImageFont.load_default()


def top_down_image(xyz: np.ndarray, label: np.ndarray, trajectory: np.ndarray | None = None,
                   res_m: float = 0.2, max_px: int = 1600, title: str = "", colors: np.ndarray | None = None,
                   names: list[str] | None = None, bounds: tuple | None = None) -> Image.Image:
    """Map seen from above: x to the right, y up; each cell shows its highest voxel's class.

    Parameters
    ----------
    xyz : (v, 3) float
        Voxel centroids, map frame, metres.
    label : (v,) uint8
        Native classes.
    trajectory : (k, 3) float, optional
        Sensor positions, drawn as a white line with a dot per scan.
    res_m : float
        Metres per pixel (grown if the map would exceed ``max_px``).
    colors : (n, 3) uint8, optional
        RGB per label (default: the class table's, for native labels).
    names : list of str, optional
        Name per label for the legend (default: the native class names).
    bounds : ((2,), (2,)), optional
        Map corners ``(lo, hi)`` in x, y, metres (default: the voxels' extent plus 2 m), so two maps
        of the same place can be drawn to the same scale.
    """
    t = class_table()
    colors = t.colors if colors is None else np.asarray(colors, np.uint8)
    names = t.names if names is None else names
    lo, hi = (xyz[:, :2].min(0) - 2.0, xyz[:, :2].max(0) + 2.0) if bounds is None else map(np.asarray, bounds)
    res = max(res_m, float((hi - lo).max()) / max_px)
    w, h = (np.ceil((hi - lo) / res).astype(int) + 1)
    col = ((xyz[:, 0] - lo[0]) / res).astype(np.int64)
    row = ((hi[1] - xyz[:, 1]) / res).astype(np.int64)
    order = np.argsort(xyz[:, 2], kind="stable")  # low first; the highest voxel wins a cell
    img = np.zeros((h, w, 3), np.uint8)
    img[row[order], col[order]] = colors[label[order]]
    canvas = Image.fromarray(img, "RGB")
    d = ImageDraw.Draw(canvas)
    if trajectory is not None and len(trajectory):
        pts = [(float((p[0] - lo[0]) / res), float((hi[1] - p[1]) / res)) for p in trajectory]
        if len(pts) > 1:
            d.line(pts, fill=(255, 255, 255), width=2)
        for x, y in pts:
            d.ellipse((x - 3, y - 3, x + 3, y + 3), outline=(255, 255, 255), fill=(0, 0, 0))
    strip = 190
    out = Image.new("RGB", (w + strip, max(h, 60 + 18 * len(names))), (24, 24, 24))
    out.paste(canvas, (0, 0))
    d = ImageDraw.Draw(out)
    y = 6
    for line in (title, f"{res:.2g} m/px, x right, y up", f"{len(xyz)} voxels"):
        if line:
            d.text((w + 8, y), line, fill=(230, 230, 230), font=_font(12))
            y += 16
    d.line((w + 8, y + 6, w + 8 + 10 / res, y + 6), fill=(255, 255, 255), width=3)
    d.text((w + 14 + 10 / res, y), "10 m", fill=(230, 230, 230), font=_font(12))
    y += 22
    counts = np.bincount(label, minlength=len(names))
    for c in np.flatnonzero(counts):
        d.rectangle((w + 8, y, w + 20, y + 12), fill=tuple(int(v) for v in colors[c]), outline=(255, 255, 255))
        d.text((w + 26, y), f"{names[c]} ({counts[c]})", fill=(255, 255, 255), font=_font(12))
        y += 18
    return out


def write_top_down(path: str | Path, *args, **kwargs) -> None:
    """Write :func:`top_down_image` as a PNG atomically."""
    img = top_down_image(*args, **kwargs)
    with atomic_path(path) as tmp:
        img.save(tmp, format="PNG")
