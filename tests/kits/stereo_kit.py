"""A KITTI stereo stream ray-cast instead of rendered (passes_2|3 EXR + JSON, image_2|3 PNG), for a frozen town.

The passes hold what a 1-sample label pass holds (class, instance and depth of the first surface on
each pixel-centre ray, :mod:`kits.fusion_kit`); the images are the class colours. Enough for the
box file's visibility and the KITTI export to run end to end without Blender.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from PIL import Image

from generator.imaging.exr import LabelledImage, write_exr
from generator.labels import class_table
from kits.fusion_kit import raycast_image


def write_raycast_stereo(root: Path, scene, spec, sweeps, width: int = 320, height: int = 160) -> None:
    """Pairs for the given sweeps of ``root/lidar/sequences/00``, exposed as generate exposes them."""
    from generator.jobs.stereo import exposure_offset
    from generator.lidar.caster import EmbreeCaster
    from generator.lidar.sensors import sensor_for_spec
    from generator.world.rig import Rig

    rig = Rig.from_spec(spec, scene)
    K = rig.K(width, height)
    caster = EmbreeCaster.from_scene(scene)
    seq = Path(root) / "lidar" / "sequences" / "00"
    offset = exposure_offset(sensor_for_spec(spec), spec.sensors.lidar.motion_skew)
    for j in sweeps:
        t = Rig.sweep_time(j) + offset
        for cam in (2, 3):
            T = rig.T_world_ego(t)[0] @ rig.T_ego_stereo(cam)
            cls, inst, depth = raycast_image(caster, scene, T, K, width, height)
            stem = f"{j:06d}"
            write_exr(seq / f"passes_{cam}" / f"{stem}.exr",
                      LabelledImage(np.zeros((height, width, 3), np.float32), cls, inst, depth))
            (seq / f"passes_{cam}" / f"{stem}.json").write_text(json.dumps(
                {"image": f"image_{cam}/{stem}.png", "camera": cam, "scan": j, "time_s": t,
                 "T_world_camera": T.tolist(), "K": K.tolist(), "width": width, "height": height}))
            (seq / f"image_{cam}").mkdir(exist_ok=True)
            Image.fromarray(class_table().colors[cls].astype(np.uint8)).save(seq / f"image_{cam}" / f"{stem}.png")
