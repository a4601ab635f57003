"""``urbangen import-carla TOWN_DIR OUT --sequence 22 [--intensity class_normal] [--domain-gap seed002]``.

Converts a KITTI-CARLA town (binary PLY frames of CARLA 0.9.10's semantic LiDAR, see
generator/formats/carla_ply.py) into OUT/sequences/NN in SemanticKITTI layout: CARLA tags
mapped to SemanticKITTI raw ids (generator/formats/carla_semantic_tags.yaml; vehicles ->
car), remission from any intensity model (default class_normal with seed 000 Table III),
optional seed 002 domain-gap processing, poses from full_poses_lidar.txt (identity without).
"""

from __future__ import annotations

import json
import logging
import os
from pathlib import Path

import numpy as np

from generator import __version__
from generator.atomic import staging, write_json
from generator.commands.intensity import add_processing_args, gap_from_args, intensity_fn_from_args
from generator.commands.options import Integer, path, sequence_id
from generator.commands.preflight import input_dir, output_dir
from generator.errors import UserError
from generator.formats import carla_ply, kitti_calib
from generator.formats import semantickitti as sk
from generator.formats.label_config import count_raw_ids, merge_counts
from generator.jobs.plan import MAX_FRAMES, check_free_space
from generator.progress import progress as progress_bar
from generator.scan_effects.pipeline import ScanProcessing, process_scan
from generator.world import rig

log = logging.getLogger(__name__)

#: Per-point fields the intensity models and the domain gap read.
IMPORT_DTYPE = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("range", "<f4"), ("cos_incidence", "<f4"),
                         ("semantic", "<u2"), ("instance", "<u2")])
#: KITTI-CARLA's cameras: 1392 x 1024 pixels, 72 deg horizontal field of view, 10 Hz.
CAMERA = {"width": 1392, "height": 1024, "hfov_deg": 72.0}
PERIOD_S = 0.1


def register(sub) -> None:
    p = sub.add_parser(
        "import-carla",
        help="convert a KITTI-CARLA town (CARLA semantic-LiDAR PLY) to a SemanticKITTI sequence",
        description=__doc__.split("\n\n")[1],
    )
    p.add_argument("town", type=path, help="KITTI-CARLA town folder (TownNN with generated/frames/*.ply)")
    p.add_argument("output", type=path, help="dataset root; the sequence goes to OUT/sequences/NN")
    p.add_argument("--sequence", required=True, type=sequence_id, help="sequence number 00..999999, e.g. 22")
    p.add_argument("--seed", type=Integer(0, 2**63 - 1), default=0,
                   help="seed of the intensity and domain-gap draws, >= 0 (default 0)")
    p.add_argument("--frames", type=Integer(1, MAX_FRAMES), default=None,
                   help=f"import only the first N frames, 1..{MAX_FRAMES}")
    add_processing_args(p)
    p.set_defaults(func=run)


def run(args) -> int:
    name = args.sequence
    input_dir(args.town, what="town folder")
    output_dir(args.output, "OUT")
    fn = intensity_fn_from_args(args, default="class_normal")
    processing = ScanProcessing(fn, gap_from_args(args), None)
    meta = import_town(args.town, args.output, name, processing, args.seed, args.frames)
    print(f"wrote {meta['frames']} scans to {args.output / 'sequences' / name} "
          f"(remission: {meta['processing']['intensity']['model']}, poses: {meta['poses']['source']})")
    return 0


class _Seed:
    """The only spec field :func:`process_scan` reads when the LiDAR weather is off."""

    def __init__(self, seed: int):
        self.seed = seed


def _instance_ids(inst: np.ndarray, table: dict[int, int], source: str) -> np.ndarray:
    """CARLA object indices -> 16-bit ids numbered 1.. in order of first appearance in the sequence (0 stays 0)."""
    uniq, inverse = np.unique(inst, return_inverse=True)
    for u in uniq:
        if u and int(u) not in table:
            table[int(u)] = len(table) + 1
    if len(table) > 0xFFFF:
        raise UserError(f"{source}: more than 65535 distinct instances in the sequence")
    return np.array([table.get(int(u), 0) for u in uniq], np.uint16)[inverse]


def import_town(town: Path, out: Path, name: str, processing: ScanProcessing, seed: int = 0,
                max_frames: int | None = None, progress: bool = True) -> dict:
    """Write ``out/sequences/<name>`` from a KITTI-CARLA town; returns its ``lidar_meta.json``.

    The sequence is staged in a temporary folder inside ``out`` and moved into place at the end.
    """
    frames, pose_file = carla_ply.find_town(town)
    frames = frames[:max_frames] if max_frames else frames
    dest = out / "sequences" / name
    if os.path.lexists(dest):
        raise UserError(f"{dest}: exists; remove it or choose another --sequence")
    if out.exists() and not out.is_dir():
        raise UserError(f"{out}: exists and is not a folder")
    poses_all, pose_times = carla_ply.read_pose_file(pose_file) if pose_file else (None, None)
    # what it writes: about the size of the PLY frames (16 + 4 bytes per point against their 24-28)
    check_free_space(out, sum(_size(p) for p in frames), f"{len(frames)} scans", flag="OUT")
    with staging(out, "import") as stage:
        seq = stage / name
        poses, times, counts, records, instances = [], [], {}, [], {}
        for k, path in enumerate(progress_bar(frames, desc=f"import-carla {name}", unit="scan", enabled=progress)):
            f = carla_ply.read_frame(path)
            pts = np.empty(len(f), IMPORT_DTYPE)
            for c in "xyz":
                pts[c] = f[c]
            xyz = np.stack([f["x"], f["y"], f["z"]], -1).astype(np.float64)
            pts["range"] = np.linalg.norm(xyz, axis=1)
            pts["cos_incidence"] = np.clip(np.abs(f["cos"]), 0.0, 1.0)
            pts["semantic"] = carla_ply.map_tags(f["tag"], str(path))
            pts["instance"] = _instance_ids(f["instance"], instances, str(path))
            start = float(np.nanmin(f["timestamp"])) if np.isfinite(f["timestamp"]).any() else float("nan")
            if poses_all is not None:
                i = carla_ply.frame_pose_index(len(poses_all), len(frames), k, start, pose_times, str(pose_file))
                poses.append(poses_all[i])
                times.append(pose_times[i] if np.isfinite(pose_times[i]) else k * PERIOD_S)
            else:
                poses.append(np.eye(4))
                times.append(start if np.isfinite(start) else k * PERIOD_S)
            pts, remission, record = process_scan(pts, processing, _Seed(seed), k)
            record["source"] = path.name
            records.append(record)
            stem = f"{k:06d}"
            sk.write_scan(seq / "velodyne" / f"{stem}.bin", np.stack([pts["x"], pts["y"], pts["z"]], -1), remission)
            sk.write_labels(seq / "labels" / f"{stem}.label", pts["semantic"], pts["instance"])
            counts = merge_counts(counts, count_raw_ids(pts["semantic"]))
        tr = np.eye(4)
        tr[:3, :3] = rig.R_BODY_OPTICAL.T  # nominal: LiDAR axes -> camera optical axes, zero offset
        k_cam = rig.intrinsics(CAMERA["hfov_deg"], CAMERA["width"], CAMERA["height"])
        calib = {f"P{i}": np.hstack([k_cam, np.zeros((3, 1))]) for i in range(4)}
        calib["Tr"] = tr[:3]
        kitti_calib.write_calib(seq / "calib.txt", calib)
        sk.write_poses(seq / "poses.txt", kitti_calib.camera_poses(np.array(poses), tr))
        t = np.array(times, np.float64)
        sk.write_times(seq / "times.txt", t - t[0])
        meta = _metadata(town, frames, pose_file, name, processing, seed, records, counts, instances)
        write_json(seq / "lidar_meta.json", meta)
        (out / "sequences").mkdir(exist_ok=True)
        seq.rename(dest)
    _label_config(out)
    return meta


def _size(path: Path) -> int:
    try:
        return path.stat().st_size
    except OSError:  # an estimate; the reader names the file that is wrong
        return 0


def _metadata(town, frames, pose_file, name, processing, seed, records, counts, instances) -> dict:
    _, tag_names = carla_ply.tag_map()
    lut, _ = carla_ply.tag_map()
    return {
        "generator": f"urbangen {__version__} import-carla",
        "format": "SemanticKITTI",
        "sequence": name,
        "frames": len(frames),
        "source": {"town": str(town), "first_frame": frames[0].name, "last_frame": frames[-1].name,
                   "format": "KITTI-CARLA binary PLY "
                             "(x, y, z, cos_angle_lidar_surface, [timestamp], instance, semantic)"},
        "seed": seed,
        "tag_map": {"file": "generator/formats/carla_semantic_tags.yaml", "carla_version": "0.9.10",
                    "tags": {str(t): {"name": n, "semantickitti": int(lut[t])} for t, n in tag_names.items()}},
        "instances": "CARLA object index -> 1.. in order of first appearance in the sequence (0 stays 0)",
        "instance_count": len(instances),
        "poses": {"source": str(pose_file) if pose_file else "identity (no full_poses_lidar.txt)",
                  "convention": "LiDAR pose at the sweep start (first packet); scans not de-skewed"},
        "calib": {"P0..P3": f"K of KITTI-CARLA's camera ({CAMERA['width']}x{CAMERA['height']}, "
                            f"hfov {CAMERA['hfov_deg']} deg), zero baselines",
                  "Tr": "nominal: LiDAR body axes -> camera optical axes, zero translation"},
        "processing": processing.describe(),
        "remission": processing.describe()["intensity"],
        "labels": "uint32: SemanticKITTI raw id (low 16 bits) | instance id (high 16 bits)",
        "points_per_scan": [r["points"] for r in records],
        "scans": records,
        "raw_id_counts": {str(k): v for k, v in sorted(counts.items())},
    }


def _label_config(out: Path) -> None:
    """Rewrite ``out/semantic-kitti.yaml`` when every sequence has metadata with counts (no label re-reading)."""
    from generator.jobs.lidar_sequence import META_NAME, write_dataset_label_config

    names = sk.list_sequences(out)
    missing = [n for n in names if not (out / "sequences" / n / META_NAME).is_file()]
    if missing:
        log.warning(
            "%s: sequences %s have no %s; semantic-kitti.yaml left as it is", out, ", ".join(missing), META_NAME
        )
        return
    try:
        write_dataset_label_config(out)
    except (ValueError, KeyError, json.JSONDecodeError) as e:
        log.warning("%s: semantic-kitti.yaml not rewritten: %s", out, e)
