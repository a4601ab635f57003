"""Where a dataset's seed-003 images live: one helper every writer and reader goes through.

Layout (``root`` is the dataset folder)::

    images/SSSS/NNNNNN_<time>_<weather>.exr          the multilayer EXR
    images/SSSS/NNNNNN_<time>_<weather>.json         its metadata (written last: present = complete)
    images/SSSS/NNNNNN_<time>_<weather>_preview.png  the preview

``NNNNNN`` is the six-digit frame number and ``SSSS`` its first four digits (``frame // 100``), so
a shard folder holds the images of 100 consecutive frames: at most 100 x 18 variants x 3 files =
5 400 entries, and ``images/`` at most 10 000 shard folders for the million frame numbers file
names allow. Both stay small enough for ``ls``, globbing and network file systems at a million
images; a frame's variants always share one folder.

Datasets written before the shards (every file flat in ``images/``) stay readable: the readers
here look in both places (:func:`find_image`, :func:`image_files`); writers always shard.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable, Iterator
from pathlib import Path

#: The images folder of a dataset.
IMAGES_DIR = "images"
#: Consecutive frames per shard folder.
SHARD_FRAMES = 100
#: Digits of a frame number in file names (``NNNNNN``).
FRAME_DIGITS = 6
#: A shard folder name: the first four digits of the frame numbers it holds.
SHARD_RE = re.compile(r"[0-9]{4}")
_STEM_RE = re.compile(r"([0-9]{6})_")


def image_name(frame_index: int, time_of_day: str = "day", weather: str = "clear") -> str:
    """File stem of an image: ``NNNNNN_<time>_<weather>``."""
    return f"{frame_index:06d}_{time_of_day}_{weather}"


def shard_name(frame: int) -> str:
    """``SSSS``: the shard folder of frame ``frame`` (0..999 999)."""
    return f"{int(frame) // SHARD_FRAMES:04d}"


def frame_of(name: str) -> int | None:
    """The frame number of an image file name or stem (``001234_day_clear.exr`` -> 1234); None if it has none."""
    m = _STEM_RE.match(Path(name).name)
    return int(m.group(1)) if m else None


def images_root(root: str | os.PathLike) -> Path:
    """``root/images``."""
    return Path(root) / IMAGES_DIR


def image_dir(root: str | os.PathLike, frame: int) -> Path:
    """The folder the images of frame ``frame`` are written to: ``root/images/SSSS``."""
    return images_root(root) / shard_name(frame)


def image_path(root: str | os.PathLike, name: str, suffix: str = ".exr") -> Path:
    """Where image ``name`` (stem ``NNNNNN_<time>_<weather>``) + ``suffix`` is written.

    ``suffix`` is the rest of the file name: ``.exr``, ``.json`` or ``_preview.png``.
    """
    frame = frame_of(name)
    if frame is None:
        raise ValueError(f"not an image name (NNNNNN_<time>_<weather>): {name[:60]!r}")
    return image_dir(root, frame) / f"{name}{suffix}"


def image_relpath(name: str, suffix: str = ".exr") -> str:
    """``images/SSSS/<name><suffix>``: the file relative to the dataset folder (URIs in OpenLABEL)."""
    frame = frame_of(name)
    if frame is None:
        raise ValueError(f"not an image name (NNNNNN_<time>_<weather>): {name[:60]!r}")
    return f"{IMAGES_DIR}/{shard_name(frame)}/{name}{suffix}"


def find_image(root: str | os.PathLike, name: str, suffix: str = ".exr") -> Path:
    """The file of image ``name`` as a reader finds it: the sharded path, else the flat one of a dataset
    written before the shards, else (neither exists) the sharded path."""
    sharded = image_path(root, name, suffix)
    if os.path.lexists(sharded):
        return sharded
    flat = images_root(root) / f"{name}{suffix}"
    return flat if os.path.lexists(flat) else sharded


def shard_dirs(root: str | os.PathLike) -> list[Path]:
    """The shard folders of ``root/images`` in frame order (not links, not files)."""
    base = images_root(root)
    if not base.is_dir():
        return []
    return sorted(p for p in base.iterdir() if SHARD_RE.fullmatch(p.name) and p.is_dir() and not p.is_symlink())


def iter_image_files(root: str | os.PathLike, pattern: str = "*.exr",
                     frames: Iterable[int] | None = None) -> Iterator[Path]:
    """Files of ``root/images`` matching ``pattern`` (a glob on the file name), folder by folder: the flat
    files of a dataset written before the shards first, then each shard in frame order, each folder
    sorted by name. Lazy: a reader that needs the first file lists one folder.

    Parameters
    ----------
    pattern : str
        ``*.exr``, ``*.json``, ``*_preview.png``, ``[0-9]*_*.exr`` ...
    frames : iterable of int, optional
        Only the shards holding these frames are listed (and only files of these frames kept),
        so a reader of a few frames does not list a million files.
    """
    base = images_root(root)
    if not base.is_dir():
        return
    wanted = None if frames is None else {int(k) for k in frames}
    dirs = [base] + (shard_dirs(root) if wanted is None else
                     [d for d in (base / s for s in sorted({shard_name(k) for k in wanted})) if d.is_dir()])
    for d in dirs:
        for p in sorted(d.glob(pattern)):
            if (wanted is None or frame_of(p.name) in wanted) and not (d is base and p.is_dir()):
                yield p


def image_files(root: str | os.PathLike, pattern: str = "*.exr", frames: Iterable[int] | None = None) -> list[Path]:
    """Every file :func:`iter_image_files` yields, sorted by file name (a frame's variants together,
    frames in order)."""
    return sorted(iter_image_files(root, pattern, frames), key=lambda p: p.name)


def has_images(root: str | os.PathLike, pattern: str = "*.exr") -> bool:
    """Whether ``root/images`` holds at least one file matching ``pattern`` (stops at the first)."""
    return next(iter_image_files(root, pattern), None) is not None


def frame_images(root: str | os.PathLike, pattern: str = "[0-9]*_*.json") -> dict[int, list[Path]]:
    """``{frame: [paths]}`` of :func:`image_files`: every weather x time variant of each frame, by name."""
    out: dict[int, list[Path]] = {}
    for p in image_files(root, pattern):
        if not p.stem.endswith("_preview"):
            out.setdefault(frame_of(p.name), []).append(p)
    return out
