"""Labelled street images written as dataset EXRs without Blender, and predictions made from them.

:func:`street_image` draws a class map with stuff, void-ish classes (street objects, other ground), things
with instance ids (cars, people, a bus, riders on bicycles) and a thing without an instance id; it varies
with the frame so images differ. :func:`perturb` turns Cityscapes label ids into a plausible wrong
prediction: classes swapped, blobs of noise, ignored ids predicted, an edge shifted.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from generator.imaging.exr import LabelledImage, write_exr
from generator.imaging.paths import image_path
from generator.labels import class_table

T = class_table()


def street_image(frame: int, h: int = 60, w: int = 96) -> LabelledImage:
    """Sky, buildings, vegetation, sidewalk, road with markings, poles, signs and things with instances."""
    rng = np.random.default_rng(100 + frame)
    cls = np.full((h, w), T.id("road"), np.uint8)
    cls[: h // 5] = T.id("sky")
    cls[h // 5: h // 2] = T.id("building")
    cls[h // 5: h // 2, w // 2 + frame % 7: w // 2 + 12] = T.id("tree_crown")
    cls[h // 2: h // 2 + 4] = T.id("sidewalk")
    cls[h // 2 + 4: h // 2 + 5] = T.id("curb")
    cls[h // 2 - 3: h // 2, 60:70] = T.id("terrain")
    cls[h - 8: h - 6, ::5] = T.id("road_marking")
    cls[h // 3: h // 2, 4:6] = T.id("pole")
    cls[h // 3: h // 3 + 3, 3:8] = T.id("traffic_sign")
    cls[h // 2 - 2: h // 2, 80:90] = T.id("street_object")
    cls[h - 4:, 90:] = T.id("other_ground")
    inst = np.zeros((h, w), np.uint32)
    things = [("car", 10 + frame), ("car", 3), ("person", 40), ("bus", 7), ("bicyclist", 8), ("ridden_bicycle", 8),
              ("truck", 0)]
    for k, (name, iid) in enumerate(things):
        r = int(rng.integers(h // 2 + 2, h - 10))
        c = 4 + 13 * k + int(rng.integers(0, 3))
        cls[r: r + 6, c: c + 10] = T.id(name)
        inst[r: r + 6, c: c + 10] = iid
    rgb = rng.uniform(0, 2, (h, w, 3)).astype(np.float32)
    depth = np.where(cls == T.id("sky"), np.inf, 10.0 + rng.uniform(0, 1, (h, w))).astype(np.float32)
    return LabelledImage(rgb, cls, inst, depth)


def write_dataset_images(root: Path, frames, variants=(("day", "clear"), ("night", "rain_fog")),
                         sequence: str = "00") -> None:
    """``root/images/SSSS/NNNNNN_<time>_<weather>.{exr,json}`` and a manifest naming the sequence."""
    for frame in frames:
        im = street_image(frame)
        for tod, weather in variants:
            name = f"{frame:06d}_{tod}_{weather}"
            image_path(root, name).parent.mkdir(parents=True, exist_ok=True)
            write_exr(image_path(root, name, ".exr"), im)
            meta = {"image": name, "frame": frame, "time_of_day": tod, "weather": {"kind": weather}}
            image_path(root, name, ".json").write_text(json.dumps(meta))
    (root / "manifest.json").write_text(json.dumps({"plan": {"sequence": sequence, "frames": list(frames)}}))


def perturb(label_ids: np.ndarray, seed: int) -> np.ndarray:
    """A wrong prediction of Cityscapes label ids: swaps, noise blobs, ignored ids, a shifted edge."""
    rng = np.random.default_rng(seed)
    p = label_ids.copy()
    h, w = p.shape
    p[p == 8] = 7 if seed % 2 else 8          # sidewalk read as road in every other image
    p[(label_ids == 26) & (rng.random(p.shape) < 0.3)] = 27   # some car pixels as truck
    p[(label_ids == 21) & (rng.random(p.shape) < 0.2)] = 22   # vegetation as terrain
    for _ in range(6):                         # blobs of random classes, void ids included
        r, c = rng.integers(0, h - 5), rng.integers(0, w - 5)
        p[r: r + 5, c: c + 5] = rng.choice([0, 4, 6, 9, 11, 17, 20, 23, 24, 25, 32, 33])
    p[:, 1:] = np.where(rng.random((h, w - 1)) < 0.05, p[:, :-1], p[:, 1:])  # jagged edges
    return p.astype(np.uint8)
