"""A nuScenes root with lidarseg made from an ``urbangen export nuscenes`` and its dataset's labels.

Our export writes no lidarseg; these helpers add one, point for point, so ``gap`` has labels to read:
each key frame's SemanticKITTI labels are turned into the nuScenes-lidarseg index that maps back to the
same learning class (``generator/labels/nuscenes_lidarseg.yaml``); classes nuScenes does not have
(parking, bicyclist, motorcyclist, trunk, pole, traffic-sign) get the index that the mapping folds them
into (road, person, person, vegetation, manmade, manmade) and unlabeled points get ``noise``.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np

from generator.formats import semantickitti as sk
from generator.labels.nuscenes_lidarseg import lidarseg_mapping
from generator.labels.sets import label_sets

#: SemanticKITTI learning classes nuScenes-lidarseg has no class of -> the class it folds them into.
FOLDED = {"parking": "road", "bicyclist": "person", "motorcyclist": "person", "trunk": "vegetation",
          "pole": "building", "traffic-sign": "building"}


def learning_to_lidarseg() -> np.ndarray:
    """(20,) uint8: for each learning class, the first lidarseg index the mapping sends to it (or its fold)."""
    m, names = lidarseg_mapping(), label_sets()["semantickitti"].names
    out = np.zeros(len(names), np.uint8)  # unlabeled -> noise (0)
    for i, n in enumerate(names[1:], 1):
        target = names.index(FOLDED.get(n, n))
        out[i] = int(np.flatnonzero(m.to_learning == target)[0])
    return out


def key_frames(nus: Path) -> list[dict]:
    """The LIDAR_TOP key-frame sample_data records of an urbangen export (one scene), in timestamp order."""
    version = next(nus.glob("v1.0-*"))
    sd = json.loads((version / "sample_data.json").read_text())
    return sorted((r for r in sd if r["is_key_frame"] and r["filename"].startswith("samples/LIDAR_TOP/")),
                  key=lambda r: r["timestamp"])


def with_lidarseg(nus: Path, dataset: Path, out: Path) -> Path:
    """A copy of the export ``nus`` at ``out`` with lidarseg from ``dataset``'s labels (sequence 00)."""
    shutil.copytree(nus, out)
    version = next(out.glob("v1.0-*"))
    seq = sk.Sequence(dataset / "lidar", "00")
    learn, lut = label_sets()["semantickitti"].from_raw, learning_to_lidarseg()
    records = []
    for k, rec in enumerate(key_frames(out)):
        _, sem, _ = seq.read_labelled(5 * k)   # key frames are every 5th sweep (2 Hz of 10 Hz)
        rel = f"lidarseg/{version.name}/{rec['token']}_lidarseg.bin"
        (out / rel).parent.mkdir(parents=True, exist_ok=True)
        (out / rel).write_bytes(lut[learn[sem]].astype(np.uint8).tobytes())
        records.append({"token": f"ls{k:04d}", "sample_data_token": rec["token"], "filename": rel})
    (version / "lidarseg.json").write_text(json.dumps(records))
    return out
