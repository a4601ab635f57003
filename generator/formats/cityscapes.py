"""Cityscapes layout: file names, label / instance / colour images, and a staged writer.

What one image becomes (``<split>`` is ``train``, ``val`` or ``test``)::

    leftImg8bit/<split>/<city>/<city>_<seq>_<frame>_leftImg8bit.png         8-bit sRGB
    gtFine/<split>/<city>/<city>_<seq>_<frame>_gtFine_labelIds.png           uint8 Cityscapes label id
    gtFine/<split>/<city>/<city>_<seq>_<frame>_gtFine_instanceIds.png        uint16, see below
    gtFine/<split>/<city>/<city>_<seq>_<frame>_gtFine_labelTrainIds.png      uint8 train id (255 = ignored)
    gtFine/<split>/<city>/<city>_<seq>_<frame>_gtFine_color.png              RGBA Cityscapes colours

Naming scheme. cityscapesScripts splits a file name at ``_`` into city, sequence and frame
and matches predictions by ``<city>_<seq>_<frame>``, refusing two ground truths with one
stem. The 12 weather x time variants of a frame share its camera pose and labels, so the
variant goes into the city: ``city = "urbangen-<time>-<weather>"`` with the weather's
``_`` written ``-`` (``urbangen-day-clear``, ``urbangen-night-rain-fog``), ``<seq>`` is
the dataset's sequence number and ``<frame>`` the frame index, each zero-padded to 6
digits: ``urbangen-night-rain-fog_000000_000003_leftImg8bit.png``.

Ids. ``labelIds`` come from the class table's ``cityscapes`` column
(:attr:`generator.labels.ClassTable.to_cityscapes`). ``instanceIds`` follow
cityscapesScripts' ``json2instanceImg``: a pixel of an instance class (:data:`INSTANCE_LABEL_IDS`:
person, rider, car, truck, bus, caravan, trailer, train, motorcycle, bicycle) with a
native instance id gets ``label id * 1000 + k``, ``k = 0, 1, ...`` numbering that class's
instances in the image in the order of their native ids; every other pixel gets its plain
label id. ``labelTrainIds`` is what cityscapesScripts' ``createTrainIdLabelImgs`` would make
(it needs polygon files, which this export does not write: the evaluation scripts read
only ``labelIds`` and ``instanceIds``).
"""

from __future__ import annotations

import logging
import os
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from PIL import Image

from generator.atomic import staging
from generator.errors import UserError
from generator.labels import class_table
from generator.labels.cityscapes import cityscapes_labels

log = logging.getLogger(__name__)

SPLITS = ("train", "val", "test")
#: cityscapesScripts' evaluation looks in ``gtFine/val`` by default.
DEFAULT_SPLIT = "val"
CITY_PREFIX = "urbangen"

#: Cityscapes labels (cityscapesScripts ``helpers/labels.py``, as data in ``generator/labels/cityscapes.yaml``):
#: id -> (name, train id, has instances, RGB colour).
LABELS: dict[int, tuple[str, int, bool, tuple[int, int, int]]] = {
    i: row[:4] for i, row in cityscapes_labels().table.items()}
INSTANCE_LABEL_IDS = cityscapes_labels().instance_ids
_TRAIN = cityscapes_labels().train_ids
_COLOR = cityscapes_labels().colors
SUFFIXES = ("leftImg8bit", "gtFine_labelIds", "gtFine_instanceIds", "gtFine_labelTrainIds", "gtFine_color")


def city_name(time_of_day: str, weather: str) -> str:
    """``urbangen-<time>-<weather>`` with no ``_`` (cityscapesScripts splits file names at ``_``)."""
    return "-".join((CITY_PREFIX, time_of_day, weather)).replace("_", "-")


def image_stem(city: str, sequence: int, frame: int) -> str:
    """``<city>_<seq:06d>_<frame:06d>``, the key cityscapesScripts matches predictions by."""
    if "_" in city:
        raise ValueError(f"city name {city!r} must not contain '_'")
    return f"{city}_{int(sequence):06d}_{int(frame):06d}"


def relative_paths(split: str, city: str, stem: str) -> dict[str, Path]:
    """Suffix -> path below the export root of every file of one image."""
    return {s: Path("leftImg8bit" if s == "leftImg8bit" else "gtFine") / split / city / f"{stem}_{s}.png"
            for s in SUFFIXES}


def label_ids(class_id: np.ndarray) -> np.ndarray:
    """(H, W) uint8 Cityscapes label ids of (H, W) native class ids."""
    return class_table().to_cityscapes[np.asarray(class_id)]


def instance_ids(labels: np.ndarray, instance: np.ndarray) -> np.ndarray:
    """(H, W) uint16 Cityscapes instance ids from label ids and native instance ids (see the module).

    Raises
    ------
    ValueError
        If a class has more than 1000 instances in the image (``k`` must stay below 1000).
    """
    out = labels.astype(np.uint16)
    inst = np.asarray(instance)
    for lid in INSTANCE_LABEL_IDS:
        on = (labels == lid) & (inst > 0)
        if not on.any():
            continue
        ids, k = np.unique(inst[on], return_inverse=True)
        if len(ids) > 1000:
            raise ValueError(f"{len(ids)} instances of Cityscapes label {lid} in one image (at most 1000)")
        out[on] = lid * 1000 + k.astype(np.uint16)
    return out


def train_ids(labels: np.ndarray) -> np.ndarray:
    """(H, W) uint8 Cityscapes train ids (255 = ignored) of label ids."""
    return _TRAIN[labels]


def color_image(labels: np.ndarray) -> np.ndarray:
    """(H, W, 4) uint8 RGBA Cityscapes colours of label ids (as ``json2labelImg`` writes ``_color``)."""
    rgba = np.full(labels.shape + (4,), 255, np.uint8)
    rgba[..., :3] = _COLOR[labels]
    return rgba


@dataclass(frozen=True)
class CityscapesImage:
    """One image to export.

    Attributes
    ----------
    source : str
        Where it came from (reported in errors and the summary).
    city, sequence, frame
        Name parts (:func:`image_stem`).
    rgb : (H, W, 3) uint8
        Display-ready sRGB.
    class_id : (H, W) uint8
        Native classes.
    instance : (H, W) uint32
        Native instance ids (0 for stuff).
    """

    source: str
    city: str
    sequence: int
    frame: int
    rgb: np.ndarray
    class_id: np.ndarray
    instance: np.ndarray


def encode(image: CityscapesImage) -> dict[str, np.ndarray]:
    """Suffix -> array of every file of one image."""
    lab = label_ids(image.class_id)
    return {"leftImg8bit": image.rgb, "gtFine_labelIds": lab, "gtFine_instanceIds": instance_ids(lab, image.instance),
            "gtFine_labelTrainIds": train_ids(lab), "gtFine_color": color_image(lab)}


def export(images: Iterable[CityscapesImage], out: str | Path, split: str = DEFAULT_SPLIT,
           planned: list[tuple[str, str]] | None = None) -> list[dict]:
    """Write ``images`` in the Cityscapes layout under ``out``, all at once or not at all.

    Parameters
    ----------
    images : iterable of CityscapesImage
    out : path-like
        Export root (created; may hold other exports, but none of the files written).
    split : {"train", "val", "test"}
    planned : list of (city, stem), optional
        The names to come, checked for duplicates and existing files before any image is read.

    Returns
    -------
    list of dict
        Per image: source, stem and the files written (relative to ``out``).
    """
    if split not in SPLITS:
        raise UserError(f"--split: must be one of {', '.join(SPLITS)}, got {split!r}")
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise UserError(f"{out}: exists and is not a folder")
    names = [stem for _, stem in planned or []]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise UserError(f"{out}: two images would both be named {dup[0]} (same frame, time and weather)")
    for city, stem in planned or []:
        _check_free(out, split, city, stem)
    seen: dict[str, str] = {}
    written: list[dict] = []
    with staging(out, "cityscapes") as stage:
        for im in images:
            stem = image_stem(im.city, im.sequence, im.frame)
            if stem in seen:
                raise UserError(f"{im.source}: same Cityscapes name {stem} as {seen[stem]}")
            seen[stem] = im.source
            _check_free(out, split, im.city, stem)
            paths = relative_paths(split, im.city, stem)
            for suffix, arr in encode(im).items():
                dest = stage / paths[suffix]
                dest.parent.mkdir(parents=True, exist_ok=True)
                Image.fromarray(arr).save(dest)
            written.append({"source": im.source, "stem": stem, "files": [str(p) for p in paths.values()]})
        if not written:
            raise UserError(f"{out}: nothing to export")
        for rec in written:  # everything is in the stage: move it into place
            for rel in rec["files"]:
                (out / rel).parent.mkdir(parents=True, exist_ok=True)
                os.replace(stage / rel, out / rel)
    log.info("exported %d images to %s (%s)", len(written), out, split)
    return written


def _check_free(out: Path, split: str, city: str, stem: str) -> None:
    for rel in relative_paths(split, city, stem).values():
        if (out / rel).exists():
            raise UserError(f"{out / rel}: exists; remove it or choose another output folder")
