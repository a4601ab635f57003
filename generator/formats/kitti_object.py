"""KITTI 3D object files: ``label_2`` lines and per-sample ``calib`` (object devkit readme conventions).

``label_2/NNNNNN.txt``: one object per line, 15 fields (16 with a detection's score)::

    type truncated occluded alpha x1 y1 x2 y2 h w l x y z rotation_y [score]

* ``type``: Car, Van, Truck, Pedestrian, Person_sitting, Cyclist, Tram, Misc or DontCare;
* ``truncated`` in [0, 1]: share of the object leaving the image; ``occluded`` 0..3 (0 fully visible,
  1 partly occluded, 2 largely occluded, 3 unknown);
* ``alpha``: observation angle, ``rotation_y - atan2(x, z)`` wrapped to [-pi, pi];
* ``x1 y1 x2 y2``: 2D box in pixels, 0-based indices of the first and last pixel column and row;
* ``h w l``: height, width, length in metres; ``x y z``: the centre of the box's BOTTOM face in the
  rectified camera-2 frame (x right, y down, z forward); ``rotation_y`` about the camera's y axis in
  [-pi, pi], 0 when the length axis points along camera x.
* DontCare regions: ``DontCare -1 -1 -10 x1 y1 x2 y2 -1 -1 -1 -1000 -1000 -1000 -10``.

``calib/NNNNNN.txt``: ``P0..P3`` (3 x 4), ``R0_rect`` (3 x 3), ``Tr_velo_to_cam`` and ``Tr_imu_to_velo``
(3 x 4), row-major, one matrix per line.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from generator.errors import SpecError
from generator.labels.detection import KITTI_TYPES
from generator.safeload import read_text

FIELDS = ("type", "truncated", "occluded", "alpha", "x1", "y1", "x2", "y2", "h", "w", "l", "x", "y", "z",
          "rotation_y", "score")
#: Longest label file read (a KITTI frame has at most a few dozen objects).
MAX_LABEL_BYTES = 4 * 1024 * 1024


@dataclass(frozen=True)
class KittiObject:
    """One line of a KITTI label file (see the module docstring; ``score`` only for detections)."""

    type: str
    truncated: float
    occluded: int
    alpha: float
    bbox: tuple[float, float, float, float]
    dimensions: tuple[float, float, float]     # h, w, l
    location: tuple[float, float, float]       # x, y, z (bottom centre, camera frame)
    rotation_y: float
    score: float | None = None

    def line(self) -> str:
        """The label line (``%.2f`` as KITTI's own files, angles and scores with more digits)."""
        out = [self.type, f"{self.truncated:.2f}", str(int(self.occluded)), f"{self.alpha:.4f}",
               *(f"{v:.2f}" for v in self.bbox), *(f"{v:.2f}" for v in self.dimensions),
               *(f"{v:.2f}" for v in self.location), f"{self.rotation_y:.4f}"]
        if self.score is not None:
            out.append(f"{self.score:.6f}")
        return " ".join(out)


def dont_care(bbox) -> KittiObject:
    """A DontCare region (an object the labels leave out) over ``bbox``."""
    return KittiObject("DontCare", -1.0, -1, -10.0, tuple(float(v) for v in bbox), (-1.0, -1.0, -1.0),
                       (-1000.0, -1000.0, -1000.0), -10.0)


def wrap(angle):
    """Angle(s) wrapped to [-pi, pi)."""
    return (np.asarray(angle) + np.pi) % (2 * np.pi) - np.pi


def write_labels(objects: list[KittiObject]) -> str:
    """The text of a label file (one line per object, newline-terminated; empty for none)."""
    return "".join(o.line() + "\n" for o in objects)


def parse_labels(text: str, source: str, predictions: bool = False) -> list[KittiObject]:
    """Parse a KITTI label file.

    Parameters
    ----------
    predictions : bool
        A detection file: every line needs the 16th field (score).

    Raises
    ------
    generator.errors.SpecError
        One line naming the file, the line and field and why (never the content).
    """
    out = []
    for n, raw in enumerate(text.splitlines(), 1):
        parts = raw.split()
        if not parts:
            continue
        where = f"line {n}"
        if len(parts) not in (15, 16) or (predictions and len(parts) != 16):
            need = "16 fields (15 and a score)" if predictions else "15 fields (16 with a score)"
            raise SpecError(source, where, f"needs {need}, has {len(parts)} (a truncated or damaged label line)")
        if parts[0] not in KITTI_TYPES:
            raise SpecError(source, f"{where}: type", f"unknown KITTI type; one of {', '.join(KITTI_TYPES)}")
        vals = []
        for name, p in zip(FIELDS[1:], parts[1:], strict=False):
            try:
                v = float(p)
            except ValueError:
                raise SpecError(source, f"{where}: {name}", "must be a number") from None
            if not np.isfinite(v):
                raise SpecError(source, f"{where}: {name}", "must be a finite number (NaN or inf found)")
            vals.append(v)
        trunc, occ, alpha, *rest = vals
        if occ not in (-1, 0, 1, 2, 3):
            raise SpecError(source, f"{where}: occluded", "must be an integer 0..3 (-1 for DontCare)")
        bbox, dims, loc, ry = tuple(rest[0:4]), tuple(rest[4:7]), tuple(rest[7:10]), rest[10]
        if parts[0] != "DontCare" and (min(dims) <= 0 or bbox[2] < bbox[0] or bbox[3] < bbox[1]):
            field = "h w l" if min(dims) <= 0 else "x1 y1 x2 y2"
            raise SpecError(source, f"{where}: {field}", "must be positive sizes / a box with x1 <= x2, y1 <= y2")
        out.append(KittiObject(parts[0], trunc, int(occ), alpha, bbox, dims, loc, ry,
                               rest[11] if len(rest) > 11 else None))
    return out


def read_labels(path, predictions: bool = False) -> list[KittiObject]:
    """:func:`parse_labels` of a file (read through :mod:`generator.safeload`)."""
    return parse_labels(read_text(path, max_bytes=MAX_LABEL_BYTES), str(path), predictions)


def calib_text(P: dict[str, np.ndarray], R0_rect: np.ndarray, Tr_velo_to_cam: np.ndarray,
               Tr_imu_to_velo: np.ndarray) -> str:
    """The text of a KITTI object ``calib`` file.

    Parameters
    ----------
    P : dict
        ``"P0"``..``"P3"`` (3, 4) float64 projections of the rectified cameras (camera 2 the reference).
    R0_rect : (3, 3) float64
    Tr_velo_to_cam, Tr_imu_to_velo : (3, 4) or (4, 4) float64
    """
    def row(m):
        return " ".join(f"{v:.12e}" for v in np.asarray(m, np.float64).reshape(-1))

    lines = [f"{k}: {row(P[k])}" for k in ("P0", "P1", "P2", "P3")]
    lines += [f"R0_rect: {row(R0_rect)}", f"Tr_velo_to_cam: {row(np.asarray(Tr_velo_to_cam)[:3])}",
              f"Tr_imu_to_velo: {row(np.asarray(Tr_imu_to_velo)[:3])}"]
    return "\n".join(lines) + "\n"


def kitti_object(record, vis, T_cam_world: np.ndarray, kitti_type: str) -> KittiObject:
    """The label line of one box seen in one image.

    Parameters
    ----------
    record : generator.detection.BoxRecord
        The box at the image's exposure instant (world frame).
    vis : generator.detection.visibility.ImageBox
        Its visibility in the image (truncation, occlusion, amodal 2D box).
    T_cam_world : (4, 4) float64
        World -> the rectified camera-2 frame at the exposure instant.
    kitti_type : str
    """
    from generator.detection.frames import box_in_frame, kitti_rotation_y

    c, R = box_in_frame(record.center, record.yaw, T_cam_world)
    length, width, height = (float(v) for v in record.size)
    bottom = c - R[:, 2] * height / 2          # the box's up axis points along -y in a level camera
    ry = float(wrap(kitti_rotation_y(R)))
    alpha = float(wrap(ry - np.arctan2(bottom[0], bottom[2])))
    x0, y0, x1, y1 = (float(v) for v in vis.bbox_amodal)
    return KittiObject(kitti_type, float(np.clip(vis.truncation, 0, 1)), int(vis.occlusion), alpha,
                       (x0, y0, x1 - 1, y1 - 1), (height, width, length), tuple(float(v) for v in bottom), ry)


def dont_care_of(vis) -> KittiObject:
    """The DontCare region of a thing the labels leave out, over its visible pixels."""
    x0, y0, x1, y1 = (float(v) for v in vis.bbox_visible)
    return dont_care((x0, y0, x1 - 1, y1 - 1))
