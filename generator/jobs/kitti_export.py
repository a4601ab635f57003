"""A dataset as KITTI 3D object data (``urbangen export kitti-object DIR OUT``).

Every stereo pair of every LiDAR sequence that has a box file (``DIR/boxes/NN.npz``) is one KITTI
sample, numbered ``000000..`` in (sequence, sweep) order::

    OUT/training/velodyne/NNNNNN.bin    the sweep's scan (float32 x, y, z, reflectance; LiDAR frame, raw)
    OUT/training/image_2/NNNNNN.png     left image (image_3: right)
    OUT/training/label_2/NNNNNN.txt     the 15 KITTI fields per object (generator.formats.kitti_object)
    OUT/training/calib/NNNNNN.txt       P0..P3 (the image's intrinsics), R0_rect (identity: the pair is rectified),
                                        Tr_velo_to_cam (LiDAR -> camera 2), Tr_imu_to_velo (ego -> LiDAR)
    OUT/ImageSets/train.txt, val.txt, trainval.txt, test.txt (empty: no testing/ split)
    OUT/mapping.txt                     sample id, sequence, sweep

Labels: every thing whose footprint touches image_2 and that has at least ``min_points`` LiDAR
points in the sweep gets its KITTI type (``generator/labels/detection.yaml``), its box at the
image's exposure instant in the camera-2 frame, truncation, occlusion level and its amodal 2D box;
a thing seen in the image but with fewer points (too far or hidden from the LiDAR) is a DontCare
region over its visible pixels, as KITTI marks objects its annotators could not label. Things
outside the image are not labelled (KITTI labels the camera's view only).

Split: per sequence, the first ``1 - val_share`` of the samples train, the rest val (contiguous,
so neighbouring sweeps of one drive do not straddle the split).
"""

from __future__ import annotations

import logging
import shutil
from pathlib import Path

import numpy as np

from generator.atomic import staging
from generator.errors import UserError
from generator.formats import semantickitti as sk
from generator.formats.box_file import read_box_file
from generator.formats.kitti_calib import read_calib, tr_matrix
from generator.formats.kitti_object import calib_text, dont_care_of, kitti_object, write_labels
from generator.labels.detection import detection_classes

log = logging.getLogger(__name__)


def _samples(root: Path, sequences) -> list[tuple[str, int, object, object]]:
    """``(sequence, sweep, box file, image_2 entry)`` of every stereo pair with a box file."""
    out = []
    for name in sequences:
        path = root / "boxes" / f"{name}.npz"
        if not path.is_file():
            raise UserError(f"{path}: missing (generate writes it; for an older dataset: urbangen openlabel SPEC DIR)")
        bf = read_box_file(path)
        for key in sorted(k for k in bf.image_names if k.startswith("image_2/")):
            j = int(key.split("/")[1])
            seq_dir = root / "lidar" / "sequences" / name
            if (seq_dir / "image_2" / f"{j:06d}.png").is_file() and (seq_dir / "velodyne" / f"{j:06d}.bin").is_file():
                out.append((name, j, bf, bf.image(key)))
    return out


def projections(K: np.ndarray, baseline_m: float) -> dict[str, np.ndarray]:
    """KITTI ``P0``..``P3`` of the rectified pair whose left camera (2, the reference) has intrinsics ``K``
    (the image's own, as rendered): ``P2 = P0 = K [I | 0]``, ``P3 = P1 = K [I | (-baseline, 0, 0)]``."""
    left = np.hstack([K, np.zeros((3, 1))])
    right = np.hstack([K, (K @ np.array([-baseline_m, 0.0, 0.0]))[:, None]])
    return {"P0": left, "P1": right, "P2": left, "P3": right}


def labels_of(entry, bf_info: dict, min_points: int) -> list:
    """The KITTI label objects of one image_2 entry (see the module docstring): the labelled things, then the
    DontCare regions, as KITTI's files order them (OpenPCDet's reader takes the non-DontCare rows first)."""
    dc = detection_classes()
    T_cam_world = np.linalg.inv(entry.T_world_camera)
    things, regions = [], []
    for rec, vis in entry.boxes:
        if rec.num_lidar_pts >= max(min_points, 1):
            things.append(kitti_object(rec, vis, T_cam_world, dc.kitti_type(rec.cls, rec.kind)))
        elif vis.pixels_visible > 0:
            regions.append(dont_care_of(vis))
    return things + regions


def export_kitti_object(root: Path, out: Path, sequences: list[str] | None = None, min_points: int = 1,
                        val_share: float = 0.5) -> dict:
    """Write the KITTI object layout of dataset ``root`` into ``out`` (staged, moved in at the end).

    Returns
    -------
    dict
        ``samples``, ``train``, ``val``, ``objects`` (by KITTI type).
    """
    root, out = Path(root), Path(out)
    sequences = sequences or sk.list_sequences(root / "lidar")
    samples = _samples(root, sequences)
    if not samples:
        raise UserError(f"{root}: no stereo pairs with boxes to export (boxes/NN.npz lists no image_2 entries)")
    if (out / "training").exists() or (out / "ImageSets").exists():
        raise UserError(f"{out}: already holds a KITTI export (training/ or ImageSets/); choose a new folder")
    counts: dict[str, int] = {}
    train, val, mapping = [], [], []
    with staging(out, "kitti") as stage:
        for sub in ("velodyne", "image_2", "image_3", "label_2", "calib"):
            (stage / "training" / sub).mkdir(parents=True)
        by_seq: dict[str, list] = {}
        for k, (name, j, bf, entry) in enumerate(samples):
            by_seq.setdefault(name, []).append(k)
            sid = f"{k:06d}"
            seq_dir = root / "lidar" / "sequences" / name
            shutil.copyfile(seq_dir / "velodyne" / f"{j:06d}.bin", stage / "training" / "velodyne" / f"{sid}.bin")
            for cam in (2, 3):
                src = seq_dir / f"image_{cam}" / f"{j:06d}.png"
                if src.is_file():
                    shutil.copyfile(src, stage / "training" / f"image_{cam}" / f"{sid}.png")
            labels = labels_of(entry, bf.info, min_points)
            for o in labels:
                counts[o.type] = counts.get(o.type, 0) + 1
            (stage / "training" / "label_2" / f"{sid}.txt").write_text(write_labels(labels))
            calib = read_calib(seq_dir / "calib.txt")
            T_ego_lidar = np.asarray(bf.info["T_ego_lidar"], np.float64)
            (stage / "training" / "calib" / f"{sid}.txt").write_text(calib_text(
                projections(entry.K, float(bf.info.get("baseline_m", 0.54))), np.eye(3),
                tr_matrix(calib, str(seq_dir / "calib.txt")), np.linalg.inv(T_ego_lidar)))
            mapping.append(f"{sid} {name} {j:06d}")
        for ids in by_seq.values():
            n_train = len(ids) - int(round(len(ids) * val_share)) if len(ids) > 1 else len(ids)
            train += ids[:n_train]
            val += ids[n_train:]
        sets = stage / "ImageSets"
        sets.mkdir()
        for name, ids in (("train", train), ("val", val), ("trainval", sorted(train + val)), ("test", [])):
            (sets / f"{name}.txt").write_text("".join(f"{k:06d}\n" for k in ids))
        (stage / "mapping.txt").write_text("".join(m + "\n" for m in mapping))
        for item in ("training", "ImageSets", "mapping.txt"):
            (stage / item).replace(out / item)
    return {"samples": len(samples), "train": len(train), "val": len(val), "objects": dict(sorted(counts.items()))}
