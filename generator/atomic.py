"""Atomic file writes: a file appears whole or not at all.

Every writer in urbangen goes through :func:`atomic_path` or one of the helpers
below: data is written to a temporary file in the destination directory and moved
into place with :func:`os.replace` (atomic on POSIX within one file system). A
crash or SIGKILL leaves at most a ``.tmp-*`` file, never a truncated output.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

TMP_PREFIX = ".tmp-"


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike, suffix: str | None = None) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; on success rename it to ``path``.

    Parameters
    ----------
    path : path-like
        Final destination. Its parent directory is created if missing.
    suffix : str, optional
        Suffix of the temporary file (some writers pick the format from it);
        defaults to the destination's suffix.
    """
    dest = Path(path)
    dest.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(
        prefix=TMP_PREFIX + dest.name + ".", suffix=dest.suffix if suffix is None else suffix, dir=dest.parent
    )
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        yield tmp_path
        os.chmod(tmp_path, 0o644)
        os.replace(tmp_path, dest)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            tmp_path.unlink()
        raise


def write_bytes(path: str | os.PathLike, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically."""
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)


def write_text(path: str | os.PathLike, text: str) -> None:
    """Write UTF-8 ``text`` to ``path`` atomically."""
    write_bytes(path, text.encode("utf-8"))


def write_json(path: str | os.PathLike, obj: Any, indent: int = 2) -> None:
    """Write ``obj`` as JSON (sorted keys are not forced; order is kept) atomically."""
    write_text(path, json.dumps(obj, indent=indent, allow_nan=False) + "\n")


def clean_temporaries(root: str | os.PathLike) -> int:
    """Remove leftover ``.tmp-*`` files under ``root`` (after a killed run).

    Returns
    -------
    int
        Number of files removed.
    """
    n = 0
    for p in Path(root).rglob(TMP_PREFIX + "*"):
        if p.is_file():
            p.unlink()
            n += 1
    return n


def inside(root: str | os.PathLike, *parts: str) -> Path:
    """``root/parts...``, refusing any result that escapes ``root`` (names from specs are untrusted).

    Raises
    ------
    ValueError
        If the joined path is absolute or leaves ``root`` (``..``, symlinks).
    """
    base = Path(root).resolve()
    target = base.joinpath(*parts).resolve()
    if target != base and base not in target.parents:
        raise ValueError(f"refusing path outside the output folder: {'/'.join(parts)}")
    return target


@contextlib.contextmanager
def staging(out: str | os.PathLike, label: str) -> Iterator[Path]:
    """Yield a temporary folder inside ``out`` for building outputs that appear all at once.

    The caller builds files in the stage and moves them into ``out`` before leaving the
    block. On any error the stage is removed, and ``out`` too when this call created it
    (with any missing parents it created), so a failed run leaves nothing behind; on
    success only the (emptied) stage is removed.
    """
    out = Path(out)
    top = out  # the outermost folder this call creates (out's missing parents included), if any
    while not top.parent.exists() and top.parent != top:
        top = top.parent
    created = not out.exists()
    stage = None
    try:
        out.mkdir(parents=True, exist_ok=True)
        stage = Path(tempfile.mkdtemp(prefix=f"{TMP_PREFIX}{label}-", dir=out))
        yield stage
    except BaseException:
        if stage is not None:
            shutil.rmtree(stage, ignore_errors=True)
        if created:
            shutil.rmtree(top, ignore_errors=True)
        raise
    shutil.rmtree(stage, ignore_errors=True)
