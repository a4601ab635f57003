"""``urbangen openlabel SPEC DIR [--sequence NN] [--classes car truck person] [--min-points N]``.

Writes ``DIR/openlabel/NN.json`` (ASAM OpenLABEL 1.0, validated against its schema) for the
LiDAR sequence ``DIR/lidar/sequences/NN`` cast from SPEC: coordinate systems (odom,
vehicle-iso8855, lidar, camera), camera and LiDAR streams, the ego transform per frame, and
per frame a cuboid in the vehicle frame with the LiDAR point count of every object of the
chosen classes that has at least ``--min-points`` points (default
``spec.labels.openlabel_min_points``).
"""

from __future__ import annotations

import json
import logging
from pathlib import Path

import numpy as np

from generator.errors import UserError

log = logging.getLogger(__name__)

DEFAULT_CLASSES = ("car", "truck", "person")


def register(sub) -> None:
    p = sub.add_parser("openlabel", help="OpenLABEL 1.0 cuboids with LiDAR point counts for a sequence",
                       description=__doc__.split("\n\n")[1])
    p.add_argument("spec", help="scene spec JSON the sequence was cast from")
    p.add_argument("dataset", type=Path, help="dataset folder (reads lidar/sequences/NN, writes openlabel/NN.json)")
    p.add_argument("--sequence", default="00", help="sequence (default 00)")
    p.add_argument("--classes", nargs="+", default=list(DEFAULT_CLASSES),
                   help=f"object classes (thing classes of the class table; default {' '.join(DEFAULT_CLASSES)})")
    p.add_argument("--min-points", type=int, default=None,
                   help="leave out objects with fewer LiDAR points in a frame (default: spec labels.openlabel_min_points)")
    p.set_defaults(func=run)


def _camera(root: Path, seq, meta: dict, spec) -> tuple[np.ndarray, int, int, str]:
    """Intrinsics from the first image's metadata, else from calib.txt and the sequence metadata."""
    images = sorted((root / "images").glob("*.json")) if (root / "images").is_dir() else []
    for p in images:
        try:
            cam = json.loads(p.read_text(encoding="utf-8"))["camera"]["intrinsics"]
            return np.asarray(cam["K"], np.float64), int(cam["width"]), int(cam["height"]), f"metadata of {p.name}"
        except (OSError, ValueError, KeyError):
            continue
    if seq.calib is None or "calib" not in meta:
        raise UserError(f"{seq.dir}: no image metadata and no calib.txt/lidar_meta.json to read the camera from")
    w, h = meta["calib"]["resolution"]
    return np.asarray(seq.calib["P2"], np.float64)[:, :3], int(w), int(h), "calib.txt P2"


def run(args) -> int:
    from generator import rig
    from generator.atomic import inside
    from generator.formats import semantickitti as sk
    from generator.formats.openlabel import build_openlabel, object_counts, write_openlabel
    from generator.labels import class_table
    from generator.layout.assemble import build_scene
    from generator.layout.frames import plan_frames
    from generator.lidar.scan import sensor_mount
    from generator.spec import load_spec

    spec = load_spec(args.spec)
    table = class_table()
    bad = [c for c in args.classes if c not in table.names or not table[c].thing]
    if bad:
        things = [r.name for r in table.rows if r.thing]
        raise UserError(f"--classes: {', '.join(bad)} not a thing class; choose from {', '.join(things)}")
    min_points = spec.labels.openlabel_min_points if args.min_points is None else args.min_points
    if min_points < 0:
        raise UserError(f"--min-points: must be >= 0, got {min_points}")
    name = sk.sequence_name(args.sequence)
    root: Path = args.dataset
    seq = sk.Sequence(root / "lidar", name)
    meta_path = seq.dir / "lidar_meta.json"
    try:
        meta = json.loads(meta_path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as e:
        raise UserError(f"{meta_path}: cannot read ({e}); the sequence must come from urbangen lidar") from None
    if meta.get("scene", {}).get("spec_hash") != spec.spec_hash:
        raise UserError(f"{meta_path}: cast from another spec (spec_hash differs from {args.spec})")
    if not seq.has_labels or not seq.frames:
        raise UserError(f"{seq.dir}: needs scans with labels")
    if seq.times is None:
        raise UserError(f"{seq.dir / 'times.txt'}: missing")
    scene = build_scene(spec)
    route = int(meta["scene"].get("route", 0))
    frames = plan_frames(scene, spec, max(seq.frames) + 1, route=route)
    frames = [frames[k] for k in seq.frames]
    counts = []
    for k in seq.frames:
        _, inst = sk.read_labels(seq.label_path(k))
        c = np.bincount(inst)
        counts.append({int(i): int(c[i]) for i in np.flatnonzero(c) if i > 0})
    objects = [o for o in scene.objects if o.cls in args.classes and o.instance_id > 0]
    K, w, h, k_src = _camera(root, seq, meta, spec)
    cam = spec.sensors.camera
    streams = {
        "camera": {"uri": "images/", "description": f"rig camera, hfov {cam.hfov_deg} deg, intrinsics from {k_src}"},
        "lidar": {"uri": f"lidar/sequences/{name}/velodyne/",
                  "description": f"{meta['sensor']['model']} ({meta['sensor']['name']}), {meta['sensor']['rotation_hz']} Hz",
                  "stream_properties": {"lasers": meta["sensor"]["lasers"], "range_m": meta["sensor"]["range_m"],
                                        "motion_skew": meta.get("motion_skew", False)}},
    }
    info = {"scene": spec.name, "seed": spec.seed, "spec_hash": spec.spec_hash, "sequence": name, "route": route,
            "classes": list(args.classes)}
    exr = {int(p.name[:6]): p.name for p in sorted((root / "images").glob("[0-9]*_*.exr"), reverse=True)}
    frame_uris = [{"camera": f"images/{exr.get(k, f'{k:06d}_day_clear.exr')}",
                   "lidar": f"lidar/sequences/{name}/velodyne/{k:06d}.bin"} for k in seq.frames]
    doc = build_openlabel(objects=objects, frames=frames, times=[seq.times[k] for k in seq.frames], counts=counts,
                          min_points=min_points, T_ego_lidar=sensor_mount(spec),
                          T_ego_camera_nominal=rig.camera_extrinsics(cam.xyz_m, cam.rpy_deg), K=K, width=w, height=h,
                          streams=streams, frame_uris=frame_uris, info=info)
    out = inside(root, "openlabel", f"{name}.json")
    try:
        write_openlabel(out, doc)
    except ValueError as e:  # a bug, not a user error: say so loudly
        raise RuntimeError(str(e)) from None
    per = object_counts(doc)
    print(f"wrote {out}: {len(seq.frames)} frames, " + ", ".join(
        f"{c}: {v['objects']} objects / {v['cuboids']} cuboids" for c, v in per.items()) + f" (>= {min_points} points)")
    return 0
