"""Small cast datasets with box files, for the export, process and detection-metric tests (no Blender).

* :func:`frozen_dataset`: the test town (no traffic), a ray-cast stereo pair at some sweeps
  (:mod:`kits.stereo_kit`) and ray-cast seed-003 images (:mod:`kits.fusion_kit`): cameras, visibility
  and COCO images without a render;
* :func:`traffic_dataset`: a two-block town with a handful of moving cars, a truck, a cyclist, a
  motorcyclist and pedestrians (``traffic.counts``), made as ``urbangen lidar`` makes a dataset (no
  manifest; the spec file beside it): velocities, attributes, moving boxes.
"""

from __future__ import annotations

import json
from pathlib import Path

TRAFFIC_SPEC = {
    "name": "traffic_test_town", "seed": 7,
    "town": {"blocks_x": 2, "blocks_y": 1, "block_size_m": 36, "block_size_jitter_m": 0, "margin_m": 12},
    "density": {"trees_per_100m": 4, "parked_cars_per_100m": 6, "people_per_100m": 3, "signs_per_block": 2,
                "moving_cars_per_100m": 0},
    "paths": {"spacing_m": 6},
    "traffic": {"counts": {"cars": 4, "trucks": 1, "cyclists": 1, "motorcyclists": 1, "pedestrians": 4,
                           "standing_pedestrians": 1}},
}


def _boxes(root: Path, spec, scene) -> None:
    from generator.jobs.box_labels import write_sequence_boxes
    from generator.jobs.boxes import write_sequence_openlabel

    write_sequence_boxes(spec, root, scene=scene)
    write_sequence_openlabel(spec, root, scene=scene)


def frozen_dataset(root: Path, spec, scene, sweeps: int = 21, pairs=(0, 10, 20), images: int = 2) -> Path:
    """``root`` with ``lidar/sequences/00`` (``sweeps`` sweeps), the stereo pair at ``pairs``, ``images``
    seed-003 frames, ``boxes/00.npz`` and ``openlabel/00.json``."""
    from generator.jobs.lidar_sequence import SequenceOptions, write_sequence
    from kits.fusion_kit import write_raycast_images
    from kits.stereo_kit import write_raycast_stereo

    write_sequence(scene, spec, root / "lidar", SequenceOptions(frames=sweeps, threads=2, bev=False), progress=False)
    write_raycast_stereo(root, scene, spec, pairs)
    if images:
        write_raycast_images(root, scene, spec, images)
    _boxes(root, spec, scene)
    return root


def traffic_dataset(root: Path, sweeps: int = 11) -> tuple[Path, Path]:
    """``root`` cast from :data:`TRAFFIC_SPEC` (with its box file) and the spec file it was made from."""
    from generator.jobs.lidar_sequence import SequenceOptions, write_sequence
    from generator.layout import build_scene
    from generator.spec import load_spec

    root.mkdir(parents=True, exist_ok=True)
    spec_path = root.parent / f"{root.name}_spec.json"
    spec_path.write_text(json.dumps(TRAFFIC_SPEC))
    spec = load_spec(spec_path)
    scene = build_scene(spec)
    write_sequence(scene, spec, root / "lidar", SequenceOptions(frames=sweeps, threads=2, bev=False), progress=False)
    _boxes(root, spec, scene)
    return root, spec_path
