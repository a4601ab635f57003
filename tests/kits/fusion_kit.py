"""Helpers for the fusion tests: camera images ray-cast with Embree instead of rendered.

A ray-cast "render" shoots one ray per pixel centre at the real geometry (no label proxies),
which is what Blender's real pass does; it lets the fusion pipeline run end to end in tests
without Blender.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from generator.imaging.exr import LabelledImage, write_exr
from generator.imaging.paths import image_path
from generator.labels import class_table
from generator.world import rig

SKY = class_table().id("sky")


def raycast_image(caster, scene, T_world_camera: np.ndarray, K: np.ndarray, width: int, height: int):
    """(class_id uint8, instance uint32, depth float32) seen through the pixel centres (sky: inf)."""
    d = rig.pixel_rays(K, width, height).reshape(-1, 3) @ T_world_camera[:3, :3].T
    o = np.repeat(T_world_camera[None, :3, 3], len(d), 0)
    dist, prim = caster.intersect(o, d.astype(np.float32), 1e4)
    hit = prim >= 0
    cls = np.full(len(d), SKY, np.uint8)
    inst = np.zeros(len(d), np.uint32)
    cls[hit] = scene.face_class[prim[hit]]
    inst[hit] = scene.face_instance[prim[hit]]
    depth = np.where(hit, dist, np.inf).astype(np.float32)
    return cls.reshape(height, width), inst.reshape(height, width), depth.reshape(height, width)


def write_raycast_images(root: Path, scene, spec, n_frames: int, width: int = 160, height: int = 96) -> None:
    """``root/images/SSSS/NNNNNN_day_clear.{exr,json}`` for frames 0..n-1 (the shard layout of
    :mod:`generator.imaging.paths`), ray-cast (metadata: the keys fusion reads)."""
    from generator.lidar.caster import EmbreeCaster
    from generator.world.rig import Rig

    caster = EmbreeCaster.from_scene(scene)
    K = rig.intrinsics(spec.sensors.camera.hfov_deg, width, height)
    for f in Rig.from_spec(spec, scene).frames(n_frames):
        cls, inst, depth = raycast_image(caster, scene, f.T_world_camera, K, width, height)
        name = f"{f.index:06d}_day_clear"
        write_exr(
            image_path(root, name, ".exr"), LabelledImage(np.zeros((height, width, 3), np.float32), cls, inst, depth)
        )
        meta = {"image": name, "files": {"exr": f"{name}.exr"}, "frame": f.index,
                "camera": {"T_world_camera": f.T_world_camera.tolist(), "T_ego_camera": f.T_ego_camera.tolist(),
                           "intrinsics": {"width": width, "height": height, "K": K.tolist()}},
                "ego": {"T_world_ego": f.T_world_ego.tolist()}}
        image_path(root, name, ".json").write_text(json.dumps(meta))


def write_raycast_stream(seq_dir: Path, scene, spec, scans, width: int = 640, height: int = 360) -> None:
    """The KITTI camera stream of ``scans`` ray-cast instead of rendered: ``image_2`` (black), ``semantic_2``
    (Cityscapes label ids) and ``passes_2`` EXRs, from camera 2 at the instant the LiDAR faces forward, as
    :mod:`generator.jobs.stereo` exposes it, with the pair's record (``passes_2/NNNNNN.json``: pose, K,
    exposure offset); the size must be the sequence's ``calib.txt`` resolution."""
    from PIL import Image

    from generator.jobs.stereo import exposure_offset
    from generator.lidar.caster import EmbreeCaster
    from generator.lidar.sensors import sensor_for_spec
    from generator.world.rig import Rig

    caster = EmbreeCaster.from_scene(scene)
    r = Rig.from_spec(spec, scene)
    K = r.K(width, height)
    offset = exposure_offset(sensor_for_spec(spec), spec.sensors.lidar.motion_skew)
    for k in scans:
        T_world_camera = r.T_world_ego(r.sweep_time(k) + offset)[0] @ r.T_ego_stereo(2)
        cls, inst, depth = raycast_image(caster, scene, T_world_camera, K, width, height)
        write_exr(seq_dir / "passes_2" / f"{k:06d}.exr",
                  LabelledImage(np.zeros((height, width, 3), np.float32), cls, inst, depth))
        record = {"scan": k, "exposure_offset_s": offset, "T_world_camera": T_world_camera.tolist(), "K": K.tolist(),
                  "width": width, "height": height}
        (seq_dir / "passes_2" / f"{k:06d}.json").write_text(json.dumps(record))
        for folder, arr in (("image_2", np.zeros((height, width, 3), np.uint8)),
                            ("semantic_2", class_table().to_cityscapes[cls])):
            (seq_dir / folder).mkdir(parents=True, exist_ok=True)
            Image.fromarray(arr).save(seq_dir / folder / f"{k:06d}.png")
