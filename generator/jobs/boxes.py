"""OpenLABEL 1.0 boxes of a dataset's LiDAR sequence (used by ``urbangen openlabel`` and ``generate``)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from generator.atomic import inside
from generator.errors import UserError
from generator.formats import semantickitti as sk
from generator.formats.openlabel import build_openlabel, write_openlabel
from generator.world.rig import Rig

DEFAULT_CLASSES = ("car", "truck", "person")


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


def write_sequence_openlabel(spec, root: Path, sequence: str = "00", classes=DEFAULT_CLASSES,
                             min_points: int | None = None, scene=None) -> tuple[Path, dict]:
    """Write ``root/openlabel/NN.json`` for ``root/lidar/sequences/NN`` cast from ``spec``.

    Parameters
    ----------
    classes : sequence of str
        Thing classes whose objects get cuboids.
    min_points : int, optional
        Objects with fewer LiDAR points in a frame are left out (default ``spec.labels.openlabel_min_points``).
    scene : SceneModel, optional
        The spec's scene if already built (it is rebuilt otherwise).

    Returns
    -------
    (Path, dict)
        The file written and the OpenLABEL document.
    """
    min_points = spec.labels.openlabel_min_points if min_points is None else min_points
    root = Path(root)
    name = sk.sequence_name(sequence)
    seq = sk.Sequence(root / "lidar", name)
    meta_path = seq.dir / "lidar_meta.json"
    try:
        meta = json.loads(meta_path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as e:
        raise UserError(f"{meta_path}: cannot read ({e}); the sequence must come from urbangen lidar") from None
    if meta.get("scene", {}).get("spec_hash") != spec.spec_hash:
        raise UserError(f"{meta_path}: cast from another spec (spec_hash differs from {spec.source})")
    if not seq.has_labels or not seq.frames:
        raise UserError(f"{seq.dir}: needs scans with labels")
    if seq.times is None:
        raise UserError(f"{seq.dir / 'times.txt'}: missing")
    if scene is None:
        from generator.layout.assemble import build_scene

        scene = build_scene(spec)
    route = int(meta["scene"].get("route", 0))
    rig = Rig.from_spec(spec, scene, route)
    frames = [rig.frame(k) for k in seq.frames]
    counts = []
    for k in seq.frames:
        _, inst = sk.read_labels(seq.label_path(k))
        c = np.bincount(inst)
        counts.append({int(i): int(c[i]) for i in np.flatnonzero(c) if i > 0})
    objects = [o for o in scene.objects if o.cls in classes and o.instance_id > 0]
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
            "classes": list(classes)}
    exr = {int(p.name[:6]): p.name for p in sorted((root / "images").glob("[0-9]*_*.exr"), reverse=True)}
    frame_uris = [{"camera": f"images/{exr.get(k, f'{k:06d}_day_clear.exr')}",
                   "lidar": f"lidar/sequences/{name}/velodyne/{k:06d}.bin"} for k in seq.frames]
    doc = build_openlabel(objects=objects, frames=frames, times=[seq.times[k] for k in seq.frames], counts=counts,
                          min_points=min_points, T_ego_lidar=rig.T_ego_lidar,
                          T_ego_camera_nominal=rig.T_ego_camera(), K=K, width=w, height=h,
                          streams=streams, frame_uris=frame_uris, info=info)
    out = inside(root, "openlabel", f"{name}.json")
    try:
        write_openlabel(out, doc)
    except ValueError as e:  # a bug, not a user error: say so loudly
        raise RuntimeError(str(e)) from None
    return out, doc
