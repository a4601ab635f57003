"""``urbangen flow DIR``: optical flow, stereo disparity and LiDAR scene flow of an existing dataset.

``generate`` writes them itself; this command (re)makes them for a dataset generated before, from
the passes and poses it holds: the depth and instance passes of every image, the camera poses
of their metadata, the scans with their labels and firing times, and the actors' motion, rebuilt
from the spec in ``DIR/manifest.json`` (checked against the traffic digest each sequence
recorded). No render and no ray cast. Every stream must have at least two images and every
image its depth and instance passes; everything is checked before the first file is written,
and the files appear together at the end.
"""

from __future__ import annotations

import logging
import os
from pathlib import Path

from generator.commands.options import path
from generator.commands.preflight import input_dir
from generator.errors import SpecError, UserError
from generator.imaging.paths import images_root
from generator.safeload import printable

log = logging.getLogger(__name__)


def register(sub) -> None:
    p = sub.add_parser("flow", help="optical flow, stereo disparity and LiDAR scene flow of an existing dataset",
                       description=__doc__.split("\n\n")[1])
    p.add_argument("dataset", type=path, help="dataset folder urbangen generate made (manifest.json, images/, lidar/)")
    p.set_defaults(func=run)


def _manifest(root: Path):
    """(spec, plan) of the dataset's manifest (one line when missing or damaged)."""
    from generator.jobs import manifest as mf
    from generator.jobs.generate import read_manifest
    from generator.jobs.plan import Plan
    from generator.spec.load import parse_spec

    doc = read_manifest(root)
    src = str(root / mf.NAME)
    if doc is None:
        raise UserError(f"{src}: missing: the flow rebuilds the actors' motion from the spec urbangen generate "
                        "recorded there")
    if not isinstance(doc.get("spec"), dict):
        raise SpecError(src, "spec", "must be the scene spec the dataset was made from")
    return parse_spec(doc["spec"], src), Plan.from_dict(doc["plan"])


def _one_image(stream: list, where: str) -> None:
    if len(stream) == 1:
        raise UserError(f"{where}: a stream of one image ({stream[0].name}): optical flow needs at least two images "
                        "of a stream")


def _streams(root: Path, town):
    """What one town has: its Dataset, images/ stream, KITTI-stream cameras and scans, all checked."""
    from generator.dataset import Dataset
    from generator.formats import semantickitti as sk
    from generator.jobs.motion import stereo_images
    from generator.jobs.motion_streams import check_passes, images_stream

    ds = Dataset(root, town.plan.sequence)
    images = images_stream(ds, set(town.plan.frames))
    check_passes(images)
    _one_image(images, f"{images_root(root)} (frames {min(town.plan.frames)}..{max(town.plan.frames)})")
    seq_dir = root / "lidar" / "sequences" / town.plan.sequence
    cams = stereo_images(seq_dir)
    for cam, stream in cams.items():
        check_passes(stream)
        _one_image(stream, str(seq_dir / f"image_{cam}"))
    seq = sk.Sequence(root / "lidar", town.plan.sequence) if (seq_dir / "velodyne").is_dir() else None
    if seq is not None and len(seq.frames) == 1:
        raise UserError(f"{seq_dir / 'velodyne'}: one scan: scene flow needs the next sweep")
    return ds, images, cams, seq


def _world(root: Path, town, seq):
    """The town's drive (world in time, rig), rebuilt from its spec and checked against the sequence's digest."""
    from generator.imaging import meta_fields as md
    from generator.jobs.drive import plan_drive
    from generator.layout import build_scene
    from generator.world.rig import Rig

    scene = build_scene(town.spec)
    drive = plan_drive(town.spec, scene, town.plan.frames, town.first)
    meta = {}
    if seq is not None and os.path.lexists(seq.dir / "lidar_meta.json"):
        src = str(seq.dir / "lidar_meta.json")
        meta = md.load_metadata(seq.dir / "lidar_meta.json")
        digest = md.field(meta, "traffic.digest", src, default=None)
        if drive.world.actors:
            times = seq.times if seq.times is not None else [Rig.sweep_time(j) for j in seq.frames]
            drive.world.check_digest(digest if isinstance(digest, str) else None, times, src)
    return drive, meta


def _move_in(stage: Path, root: Path) -> int:
    n = 0
    for p in sorted(stage.rglob("*")):
        if p.is_file():
            dest = root / p.relative_to(stage)
            dest.parent.mkdir(parents=True, exist_ok=True)
            os.replace(p, dest)
            n += 1
    return n


def run(args) -> int:
    from generator.atomic import staging
    from generator.jobs.motion import write_motion
    from generator.jobs.scan_flow import remove_last, write_sequence_flow
    from generator.jobs.towns import town_runs
    from generator.lidar.sensors import sensor_for_spec

    root = input_dir(args.dataset, what="dataset folder")
    spec, plan = _manifest(root)
    towns = town_runs(spec, plan)
    found = [(town, *_streams(root, town)) for town in towns]  # every check before any work
    if not any(len(imgs) > 1 or any(len(s) > 1 for s in cams.values()) or seq is not None
               for _, _, imgs, cams, seq in found):
        raise UserError(f"{printable(root)}: no images with depth and instance passes and no scans: nothing to make "
                        "flow from")
    summary = []
    with staging(root, "flow") as stage:
        for town, ds, _, _, seq in found:
            drive, meta = _world(root, town, seq)
            record = write_motion(ds, drive.world, town.plan.frames, town.plan.sequence, out=stage)
            if seq is not None:
                skew = bool(meta.get("motion_skew", town.spec.sensors.lidar.motion_skew))
                rel = seq.dir.relative_to(root)
                sensor = sensor_for_spec(town.spec)
                record["scans"] = write_sequence_flow(seq, stage / rel, drive.rig, drive.world, sensor, skew)
            summary.append((town.plan.sequence, record))
        n = _move_in(stage, root)
    for *_, seq in found:
        if seq is not None:
            remove_last(seq.dir, len(seq.frames))
    for sequence, record in summary:
        parts = [f"{k}: {v['images']} images" for k, v in record.items() if isinstance(v, dict) and "images" in v]
        if "disparity" in record:
            parts.append(f"{record['disparity']['pairs']} disparity maps")
        if "scans" in record:
            parts.append(f"{record['scans']} scene-flow scans")
        print(f"sequence {sequence}: " + ", ".join(parts))
    print(f"wrote {n} files under {root}")
    return 0
