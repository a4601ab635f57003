"""Small cast datasets with box files, for the export, process and detection-metric tests (no Blender).

* :func:`frozen_dataset`: the test town (no traffic), a ray-cast stereo pair at some sweeps
  (:mod:`kits.stereo_kit`) and ray-cast seed-003 images (:mod:`kits.fusion_kit`): cameras, visibility
  and COCO images without a render;
* :func:`traffic_dataset`: a two-block town with a handful of moving cars, a truck, a cyclist, a
  motorcyclist and pedestrians (``traffic.counts``), made as ``urbangen lidar`` makes a dataset (no
  manifest; the spec file beside it): velocities, attributes, moving boxes.

Both cast the ideal sensor (every ray's first hit): the exports and metrics are checked to put each
point in its thing's box, which the physical sensor's mixed points and range noise blur by design.
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
    "sensors": {"lidar": {"returns": "ideal"}},
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
    from kits.sensor_kit import ideal
    from kits.stereo_kit import write_raycast_stereo

    spec = ideal(spec)
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


def tiny_nuscenes(out: Path) -> Path:
    """A hand-made nuScenes dataroot (tables, splits, a map; no point files): one scene of 11 sweeps, the ego
    still at the origin, four cars 25 m apart on a ring 20 m out and two pedestrians 12 m out, unmoving, in
    every key frame -- far enough apart that a box moved by up to 3 m still has its own as nearest."""
    import numpy as np
    from PIL import Image

    from generator.formats import nuscenes as nu

    T = np.eye(4)
    T[:2, 3] = 100.0                         # the map's corner is the global origin: stay in x, y > 0
    sweeps = [nu.Sweep(j, nu.EPOCH_US + 100_000 * j, T, f"sweeps/LIDAR_TOP/{j}.pcd.bin") for j in range(11)]
    things = [("vehicle.car", "vehicle.parked", 20.0 * np.cos(a), 20.0 * np.sin(a), (4.5, 1.9, 1.5))
              for a in np.deg2rad([0, 75, 150, 225])]
    things += [("human.pedestrian.adult", "pedestrian.standing", 12.0 * np.cos(a), 12.0 * np.sin(a), (0.6, 0.6, 1.8))
               for a in np.deg2rad([40, 290])]
    anns = [nu.Annotation(j, tid + 1, cat, attr, np.array([100 + x, 100 + y, 0.8]), np.array(size), 0.3, 50)
            for j in (0, 5, 10) for tid, (cat, attr, x, y, size) in enumerate(things)]
    b = nu.TableBuilder()
    b.add_scene(nu.SceneInput("tiny-00", "hand case", "tiny", np.eye(4), sweeps, anns, [], "maps/tiny.png"))
    version = out / "v1.0-urbangen"
    version.mkdir(parents=True)
    for table, rows in b.tables().items():
        (version / f"{table}.json").write_text(json.dumps(rows))
    (version / "splits.json").write_text(json.dumps({"urbangen_val": ["tiny-00"], "urbangen_all": ["tiny-00"]}))
    (out / "maps").mkdir()
    Image.fromarray(np.full((2000, 2000), 255, np.uint8)).save(out / "maps" / "tiny.png")
    return out
