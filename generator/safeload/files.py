"""Reading user files: regular files only, size limits first, strict UTF-8, confined paths,
numeric tables and binary arrays."""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np

from generator.safeload.limits import (
    MAX_ARRAY_BYTES,
    MAX_DOCUMENT_BYTES,
    MAX_TABLE_BYTES,
    MiB,
)
from generator.safeload.messages import (
    _fail,
    _kind_problem,
    _os_reason,
    _size,
    printable,
)

# --------------------------------------------------------------------------- files


def read_bytes(path: str | os.PathLike, *, source: str | None = None, field: str = "",
               max_bytes: int = MAX_DOCUMENT_BYTES) -> bytes:
    """Read a regular file of at most ``max_bytes`` bytes.

    Parameters
    ----------
    path : path-like
        The file.
    source : str, optional
        How to name the file in messages (default: ``path`` as given).
    field : str, optional
        Field that named the file (``sensors.lidar.sensor_file``), if any.
    max_bytes : int, optional
        Size limit, checked on the size the file system reports before anything is read
        and again on what was actually read.

    Returns
    -------
    bytes
        The whole content.

    Raises
    ------
    generator.errors.SpecError
        Missing file, not a regular file (directory, FIFO, socket, device), symlink loop,
        no permission, or too large.
    """
    src = str(path) if source is None else source
    try:
        st = os.stat(path)
    except ValueError:
        _fail(src, field, "invalid path (contains a NUL byte)")
    except OSError as e:
        _fail(src, field, _os_reason(e))
    _check_stat(st, src, field, max_bytes)
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0) | getattr(os, "O_CLOEXEC", 0)
    try:
        fd = os.open(path, flags)
    except OSError as e:
        _fail(src, field, _os_reason(e))
    try:
        _check_stat(os.fstat(fd), src, field, max_bytes)  # the file opened is the file checked
        chunks, left = [], max_bytes + 1
        while left > 0:
            try:
                chunk = os.read(fd, min(left, 4 * MiB))
            except BlockingIOError:
                _fail(src, field, "is not a regular file (reading would block)")
            except OSError as e:
                _fail(src, field, _os_reason(e))
            if not chunk:
                break
            chunks.append(chunk)
            left -= len(chunk)
    finally:
        os.close(fd)
    data = b"".join(chunks)
    if len(data) > max_bytes:
        _fail(src, field, f"file too large: more than the limit of {_size(max_bytes)} (it grew while being read)")
    return data


def _check_stat(st: os.stat_result, src: str, field: str, max_bytes: int) -> None:
    problem = _kind_problem(st.st_mode)
    if problem:
        _fail(src, field, problem)
    if st.st_size > max_bytes:
        _fail(src, field, f"file too large: {_size(st.st_size)}, the limit is {_size(max_bytes)}")


def read_text(path: str | os.PathLike, *, source: str | None = None, field: str = "",
              max_bytes: int = MAX_DOCUMENT_BYTES) -> str:
    """Read a regular file as strict UTF-8 text (a leading byte-order mark is dropped).

    Parameters
    ----------
    path, source, field, max_bytes
        As for :func:`read_bytes`.

    Returns
    -------
    str
        The text.

    Raises
    ------
    generator.errors.SpecError
        Everything :func:`read_bytes` raises, or ``not UTF-8 text (byte N)``.
    """
    src = str(path) if source is None else source
    data = read_bytes(path, source=src, field=field, max_bytes=max_bytes)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as e:
        _fail(src, field, f"not UTF-8 text (byte {e.start})")
    return text.removeprefix("\ufeff")


# --------------------------------------------------------------------------- paths named in files


def confined_path(base_dir: str | os.PathLike, relative: str | os.PathLike, source: str, field: str) -> Path:
    """Resolve a path written inside a file, refusing anything outside that file's folder.

    Parameters
    ----------
    base_dir : path-like
        The folder the path is relative to (the spec's folder).
    relative : str or path-like
        The path as written in the file.
    source : str
        The file that holds the path (named in messages).
    field : str
        Its field (``sensors.lidar.sensor_file``).

    Returns
    -------
    pathlib.Path
        The resolved path (symlinks followed), inside the resolved ``base_dir``. It need
        not exist; reading it is the caller's business.

    Raises
    ------
    generator.errors.SpecError
        Empty, absolute, NUL byte, or resolving outside ``base_dir`` (``..``, or a
        symlink leading out).
    """
    rel = os.fspath(relative)
    shown = json.dumps(printable(rel, 200))
    if not rel:
        _fail(source, field, "must be a path relative to the spec's folder, got an empty string")
    if "\0" in rel:
        _fail(source, field, f"must be a path, got one with a NUL byte: {shown}")
    if os.path.isabs(rel):
        _fail(source, field, f"must be a path relative to the spec's folder, got an absolute path {shown}")
    base = os.path.realpath(base_dir)
    target = os.path.realpath(os.path.join(base, rel))
    if os.path.commonpath([base, target]) != base:
        _fail(source, field,
              f"must stay inside the spec's folder ('..' and links leading out are refused), got {shown}")
    return Path(target)


# --------------------------------------------------------------------------- tables and arrays


def read_matrix_rows(path: str | os.PathLike, ncols: int, *, source: str | None = None, field: str = "",
                     max_bytes: int = MAX_TABLE_BYTES, max_rows: int | None = None,
                     allow_empty: bool = False) -> np.ndarray:
    """Read a whitespace-separated numeric table: every line exactly ``ncols`` finite numbers.

    Blank lines at the end are ignored; a blank line elsewhere is an error (it would shift
    every later row). This is the format of KITTI ``poses.txt`` (12 columns) and ``times.txt`` (1).

    Parameters
    ----------
    path, source, field, max_bytes
        As for :func:`read_text`.
    ncols : int
        Numbers per line.
    max_rows : int, optional
        Refuse more rows than this.
    allow_empty : bool, optional
        Accept a file without rows (default: an error).

    Returns
    -------
    numpy.ndarray
        ``(rows, ncols)`` float64.

    Raises
    ------
    generator.errors.SpecError
        ``<file>: line N: expected 12 numbers, got 11`` and similar; the line is never quoted.
    """
    src = str(path) if source is None else source
    lines = read_text(path, source=src, field=field, max_bytes=max_bytes).splitlines()
    while lines and not lines[-1].strip():
        lines.pop()
    where = (lambda n: f"{field}: line {n}") if field else (lambda n: f"line {n}")
    if not lines and not allow_empty:
        _fail(src, field, "has no rows")
    if max_rows is not None and len(lines) > max_rows:
        _fail(src, field, f"has {len(lines)} rows, more than the limit of {max_rows}")
    out = np.empty((len(lines), ncols), np.float64)
    for i, line in enumerate(lines):
        parts = line.split()
        if len(parts) != ncols:
            _fail(src, where(i + 1), f"expected {ncols} numbers, got {len(parts)}")
        for j, part in enumerate(parts):
            try:
                v = float(part)
            except ValueError:
                _fail(src, where(i + 1), f"column {j + 1} is not a number")
            if not math.isfinite(v):
                _fail(src, where(i + 1), f"column {j + 1} is not a finite number")
            out[i, j] = v
    return out


def read_array(path: str | os.PathLike, dtype, record_bytes: int | None = None, *, source: str | None = None,
               field: str = "", max_bytes: int = MAX_ARRAY_BYTES, finite: bool = False) -> np.ndarray:
    """Read a flat binary array of fixed-size records (KITTI ``.bin`` scans, ``.label`` files).

    Parameters
    ----------
    path, source, field, max_bytes
        As for :func:`read_bytes`.
    dtype : numpy dtype-like
        Element type, with its byte order (``"<f4"``, ``"<u4"``).
    record_bytes : int, optional
        Bytes per record (16 for a KITTI point of four float32); default one element.
    finite : bool, optional
        Also refuse NaN/inf elements (float dtypes).

    Returns
    -------
    numpy.ndarray
        Writable; ``(records,)`` when a record is one element, else ``(records, record_bytes // itemsize)``.

    Raises
    ------
    generator.errors.SpecError
        Size not a multiple of the record size, too large, non-finite values, or any
        :func:`read_bytes` problem.
    """
    src = str(path) if source is None else source
    dt = np.dtype(dtype)
    record = dt.itemsize if record_bytes is None else int(record_bytes)
    if record <= 0 or record % dt.itemsize:
        raise ValueError(f"record_bytes {record} is not a positive multiple of {dt.itemsize}")
    data = read_bytes(path, source=src, field=field, max_bytes=max_bytes)
    if len(data) % record:
        _fail(src, field, f"size {len(data)} bytes is not a multiple of the record size ({record} bytes)")
    arr = np.frombuffer(bytearray(data), dt)
    per = record // dt.itemsize
    if per > 1:
        arr = arr.reshape(-1, per)
    if finite and dt.kind == "f":
        bad = ~np.isfinite(arr)
        if bad.any():
            first = int(np.flatnonzero(bad.reshape(len(arr), -1).any(axis=1))[0])
            _fail(src, field, f"record {first} is not finite")
    return arr
