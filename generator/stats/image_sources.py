"""Ground-truth images for ``eval --images``: a Cityscapes export, or a dataset folder's own images.

=========================================  =====================================  =========================
``--gt`` holds                              ground truth (Cityscapes label ids)     a prediction is found by
=========================================  =====================================  =========================
``gtFine/<split>/<city>/`` (an export)      ``*_gtFine_labelIds.png`` and           its stem ``<city>_<seq>_
                                            ``*_instanceIds.png``, as               <frame>*.png`` (the way
                                            cityscapesScripts reads them            cityscapesScripts does)
``images/`` (a dataset)                     the EXR class map through the class     the stem its export
                                            table, instances as the export writes   would have
``lidar/sequences/NN/image_2/``             ``semantic_2/NNNNNN.png``, instances    its file name
(the KITTI stream of a dataset)             from ``passes_2/NNNNNN.exr``            ``NNNNNN.png``
=========================================  =====================================  =========================

A dataset's images are listed by :class:`generator.dataset.Dataset` (so a sharded ``images/`` folder is
its business); each image is read only when scored.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generator.errors import UserError
from generator.formats import cityscapes as cs
from generator.formats.cityscapes_stems import dataset_sequence, image_stem_of
from generator.formats.label_png import read_label_png
from generator.imaging.exr import read_exr
from generator.imaging.paths import find_image, images_root
from generator.safeload import printable

GT_SUFFIX = "_gtFine_labelIds.png"


@dataclass
class GroundTruthImage:
    """One ground-truth image.

    Attributes
    ----------
    name : str
        Its name in tables: the Cityscapes stem or ``image_2`` file name.
    by : {"stem", "name"}
        How its prediction is found (:class:`generator.formats.prediction_files.PredictionFolder`).
    source : str
        The ground-truth file.
    load : callable
        ``() -> (label ids (H, W) int64, instanceIds (H, W) int64 or None)``.
    """

    name: str
    by: str
    source: str
    load: Callable[[], tuple[np.ndarray, np.ndarray | None]]


def cityscapes_export(root: Path, split: str) -> list[GroundTruthImage]:
    """``gtFine/<split>/*/*_gtFine_labelIds.png`` with their ``instanceIds`` (as the script globs them)."""
    out = []
    for lab in sorted((root / "gtFine" / split).glob(f"*/*{GT_SUFFIX}")):
        inst = lab.with_name(lab.name.replace("labelIds", "instanceIds"))

        def load(lab=lab, inst=inst):
            ids = read_label_png(lab)
            return ids, (read_label_png(inst, ids.shape) if os.path.lexists(inst) else None)

        out.append(GroundTruthImage(lab.name[: -len(GT_SUFFIX)], "stem", str(lab), load))
    return out


def dataset_images(root: Path, sequence: str) -> list[GroundTruthImage]:
    """The seed-003 images of a dataset (matched by export stem) and its KITTI stream (by file name)."""
    from generator.dataset import Dataset

    ds = Dataset(root, sequence)
    seq_no = dataset_sequence(root)
    out = []
    for name in ds.image_names():
        stem = image_stem_of(name, seq_no)
        if stem is None:
            continue

        def load(name=name):
            img = ds.image(name)
            lab = cs.label_ids(img.class_id)
            return lab.astype(np.int64), cs.instance_ids(lab, img.instance).astype(np.int64)

        out.append(GroundTruthImage(stem, "stem", str(find_image(root, name, ".exr")), load))
    return out + kitti_stream(root / "lidar" / "sequences" / sequence)


def kitti_stream(seq_dir: Path) -> list[GroundTruthImage]:
    """``image_2`` of a sequence: ``semantic_2/NNNNNN.png`` label ids, instances from ``passes_2``."""
    out = []
    for lab in sorted((seq_dir / "semantic_2").glob("[0-9]*.png")):
        exr = seq_dir / "passes_2" / f"{lab.stem}.exr"

        def load(lab=lab, exr=exr):
            ids = read_label_png(lab)
            if not os.path.lexists(exr):
                return ids, None
            img = read_exr(exr)
            return ids, cs.instance_ids(ids.astype(np.uint8), img.instance).astype(np.int64)

        out.append(GroundTruthImage(f"{lab.stem}.png", "name", str(lab), load))
    return out


def ground_truth(root: Path, split: str, sequence: str) -> list[GroundTruthImage]:
    """The ground-truth images of ``root`` (a Cityscapes export or a dataset folder, see the module table).

    Raises
    ------
    UserError
        ``root`` is neither, or holds no ground-truth image.
    """
    if (root / "gtFine").is_dir():
        found = cityscapes_export(root, split)
        where = f"gtFine/{split}/*/*{GT_SUFFIX}"
    elif images_root(root).is_dir() or (root / "lidar" / "sequences").is_dir():
        found = dataset_images(root, sequence)
        where = f"images/ or lidar/sequences/{sequence}/semantic_2/"
    else:
        raise UserError(f"{printable(root)}: --gt: neither a Cityscapes export (gtFine/) nor a dataset "
                        "(images/, lidar/sequences/)")
    if not found:
        raise UserError(f"{printable(root)}: --gt: no ground-truth images in {where}")
    return found
