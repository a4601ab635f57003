"""Does ``P2 @ Tr`` land where the labels say? The KITTI camera stream checked as KITTI tools use it.

For every scan of a sequence with a stereo pair (:mod:`generator.jobs.stereo`), project the
raw ``.bin`` points with ``calib.txt``'s ``P2 @ Tr`` -- no de-skew, no per-image pose, exactly
what a KITTI tool does -- into ``image_2`` and compare each point's native class (the
``native_labels/`` side file) with the class of its pixel (``passes_2/NNNNNN.exr``).

Counted points: inside the image, visible (their distance matches the rendered depth of
their pixel, :func:`generator.fusion.projection.visible`), not on a class boundary of the
label map, and not of a hull-proxy class (fences and foliage: the image labels their hull,
the beams pass their gaps).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generator.errors import UserError
from generator.formats import kitti_calib
from generator.formats import semantickitti as sk
from generator.formats.point_sidecars import NATIVE_DIR, read_sidecar
from generator.fusion import projection as P
from generator.imaging.exr import read_exr
from generator.labels import class_table


def _p2(calib: dict, source: Path) -> np.ndarray:
    """(3, 4) ``P2 = K [I | t]`` of a parsed calib, refusing anything else (it is solved for ``t``)."""
    P2 = np.asarray(calib.get("P2", np.zeros(0)), np.float64)
    if P2.shape != (3, 4) or not (P2[0, 0] > 0 and P2[1, 1] > 0 and P2[1, 0] == 0
                                  and np.array_equal(P2[2, :3], [0, 0, 1])):
        raise UserError(f"{source}: P2: needs 12 numbers forming K [I | t] (a pinhole K with fx, fy > 0)")
    return P2


@dataclass
class StreamView:
    """Scan ``index`` projected into its ``image_2`` the KITTI way (raw points, ``P2 @ Tr``).

    Attributes
    ----------
    points : int
        Points in the scan.
    proj : Projection
        The points in front of camera 2 and inside the image.
    visible : (m,) bool
        Occlusion test against ``passes_2``'s rendered depth.
    boundary : (m,) bool
        Pixel within 1 px of a class boundary of the rendered labels.
    image_class : (m,) uint8
        Native class of each projected point's pixel (rendered labels).
    shape : (H, W)
        Image size.
    """

    points: int
    proj: P.Projection
    visible: np.ndarray
    boundary: np.ndarray
    image_class: np.ndarray
    shape: tuple[int, int]


def project_scan(seq_dir: Path, index: int, calib: dict) -> StreamView:
    """Project scan ``index``'s raw ``.bin`` points into ``image_2`` with ``P2 @ Tr``, as KITTI tools do."""
    xyz = sk.read_scan(seq_dir / "velodyne" / f"{index:06d}.bin")[:, :3].astype(np.float64)
    img = read_exr(seq_dir / "passes_2" / f"{index:06d}.exr")
    h, w = img.class_id.shape
    P2 = _p2(calib, seq_dir / "calib.txt")
    K, t = P2[:, :3], np.linalg.solve(P2[:, :3], P2[:, 3])  # P2 = K [I | t]
    T = kitti_calib.homogeneous(np.c_[np.eye(3), t]) @ kitti_calib.tr_matrix(calib)
    proj = P.project(P.transform(T, xyz), K, w, h)
    return StreamView(len(xyz), proj, P.visible(proj, img.depth, K), P.boundary_mask(img.class_id)[proj.row, proj.col],
                      img.class_id[proj.row, proj.col], (h, w))


def scan_agreement(seq_dir: Path, index: int, calib: dict) -> dict:
    """Counts for scan ``index``: ``{"counted", "agree", "projected", "points"}``."""
    view = project_scan(seq_dir, index, calib)
    native = read_sidecar(seq_dir, NATIVE_DIR, index, view.points)
    if native is None:
        raise UserError(f"{seq_dir / NATIVE_DIR}: no native labels for scan {index:06d}")
    lidar_cls = native[view.proj.index]
    hull = class_table().hull_classes
    keep = view.visible & ~view.boundary & ~hull[lidar_cls] & ~hull[view.image_class]
    agree = lidar_cls[keep] == view.image_class[keep]
    return {"points": view.points, "projected": int(len(view.proj.index)), "counted": int(keep.sum()),
            "agree": int(agree.sum())}


def sequence_agreement(seq_dir: str | Path) -> dict:
    """Agreement of ``P2 @ Tr`` projections with ``image_2`` labels over every scan with a pair.

    Returns
    -------
    dict
        ``{"scans": [...per-scan counts...], "counted": n, "agree": n, "agreement": fraction}``.
    """
    seq_dir = Path(seq_dir)
    calib = kitti_calib.read_calib(seq_dir / "calib.txt")
    scans = sorted(int(p.stem) for p in (seq_dir / "passes_2").glob("[0-9]*.exr"))
    if not scans:
        raise UserError(f"{seq_dir / 'passes_2'}: no stereo pairs (generate renders them with sensors.stereo.enabled)")
    per = [{"scan": k, **scan_agreement(seq_dir, k, calib)} for k in scans]
    counted, agree = sum(r["counted"] for r in per), sum(r["agree"] for r in per)
    return {"scans": per, "counted": counted, "agree": agree, "agreement": agree / counted if counted else float("nan")}
