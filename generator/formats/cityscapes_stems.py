"""The Cityscapes stem ``urbangen export cityscapes`` gives a dataset image, without exporting it.

A dataset image ``images/NNNNNN_<time>_<weather>`` is exported as ``<city>_<seq>_<frame>`` with
``city = urbangen-<time>-<weather>`` (:func:`generator.formats.cityscapes.city_name`), ``<seq>`` the
dataset's sequence number (``plan.sequence`` of ``manifest.json``, 0 without one) and ``<frame>`` the
frame. A model's predictions on the exported ``leftImg8bit`` images carry that stem, which is how
``fuse --image-labels`` and ``eval --images`` find the prediction of each dataset image, as
cityscapesScripts does (:mod:`generator.formats.prediction_files`).
"""

from __future__ import annotations

import os
import re
from pathlib import Path

from generator.errors import UserError
from generator.formats.cityscapes import city_name, image_stem
from generator.safeload import MAX_METADATA_BYTES, load_json, printable

#: ``NNNNNN_<time>_<weather>``: the name of a dataset image (docs/dataset.md).
IMAGE_NAME = re.compile(r"^(\d{6})_([a-z]+)_([a-z_]+)$")


def dataset_sequence(root: str | Path) -> int:
    """The sequence number the Cityscapes export of dataset ``root`` uses (``plan.sequence``; 0 without a manifest)."""
    path = Path(root) / "manifest.json"
    if not os.path.lexists(path):
        return 0
    manifest = load_json(path, max_bytes=MAX_METADATA_BYTES, max_nodes=10_000_000)
    plan = manifest.get("plan", {}) if isinstance(manifest, dict) else {}
    seq = str(plan.get("sequence", "0") if isinstance(plan, dict) else "?")
    if not (seq.isascii() and seq.isdigit() and len(seq) <= 4):
        raise UserError(f"{path}: plan.sequence must be a number, got {printable(seq, 40)!r}")
    return int(seq)


def image_stem_of(name: str, sequence: int) -> str | None:
    """``<city>_<seq>_<frame>`` of dataset image ``name`` (``000003_night_rain_fog``), or None for another name."""
    m = IMAGE_NAME.match(name)
    if not m:
        return None
    return image_stem(city_name(m.group(2), m.group(3)), sequence, int(m.group(1)))
