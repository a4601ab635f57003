"""Where a dataset's seed-003 images are: the one place that knows the layout of ``images/``.

Images are named ``NNNNNN_<time>_<weather>.{exr,json}`` (plus ``_preview.png``); they may sit
directly in ``images/`` or in sub-folders of it (a sharded dataset), so every reader finds them here.
"""

from __future__ import annotations

import re
from pathlib import Path

_STEM = re.compile(r"^[0-9]{6}_[a-z]+_[a-z_]+$")


def image_files(root: str | Path, ext: str = "json") -> list[Path]:
    """Every image file with suffix ``ext`` (``"json"`` metadata or ``"exr"``) of the dataset ``root``,
    sorted by name (frame, time, weather); previews and other files are left out."""
    folder = Path(root) / "images"
    if not folder.is_dir():
        return []
    found = [p for p in folder.rglob(f"*.{ext}") if _STEM.match(p.stem) and not p.stem.endswith("_preview")]
    return sorted(found, key=lambda p: p.name)


def frame_images(root: str | Path, ext: str = "json") -> dict[int, list[Path]]:
    """``{frame: [paths]}`` of :func:`image_files`: every weather x time variant of each frame."""
    out: dict[int, list[Path]] = {}
    for p in image_files(root, ext):
        out.setdefault(int(p.name[:6]), []).append(p)
    return out
