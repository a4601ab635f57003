"""Checks on the paths a user names on the command line, made before any work or write.

Paths given on the command line are the user's choice: they may point anywhere, but they
must be what the command needs. An input folder must be a folder; an output folder must
be a folder or not exist yet (its nearest existing ancestor a writable folder); an output
file must be a regular file or not exist yet. Anything else -- a file where a folder is
expected, a named pipe, a device (writing "into" ``/dev/null`` would replace it), a
symlink loop, a path through a file -- is one :class:`~generator.errors.UserError` line
naming the option and the path, before anything is read or written.
"""

from __future__ import annotations

import errno
import os
import re
import stat
from pathlib import Path

from generator.atomic import TMP_PREFIX
from generator.errors import UserError
from generator.safeload import file_kind, printable

#: Longest file name component most file systems take (bytes).
NAME_MAX = 255

_REASONS = {
    errno.ENOENT: "no such file or folder",
    errno.ENOTDIR: "a part of the path is not a folder",
    errno.ELOOP: "too many levels of symbolic links (a symlink loop)",
    errno.EACCES: "permission denied",
    errno.EPERM: "permission denied",
    errno.ENAMETOOLONG: "path too long",
    errno.EROFS: "read-only file system",
    errno.ENOSPC: "no space left on device",
    errno.EDQUOT: "disk quota exceeded",
    errno.EISDIR: "is a folder",
    errno.EEXIST: "already exists",
    errno.EBUSY: "busy (a mount point or in use)",
    errno.EXDEV: "on another file system",
}


def os_reason(e: OSError) -> str:
    """A short reason for an :class:`OSError` (no file content, just what the system said)."""
    if e.errno in _REASONS:
        return _REASONS[e.errno]
    if e.strerror:
        return e.strerror.lower()
    text = str(e).strip().splitlines()  # an OSError of a library (Ray's ConnectionError): its own words
    return printable(text[0], 300) if text else type(e).__name__


_ATOMIC_TMP = re.compile(re.escape(TMP_PREFIX) + r"(.+)\.[A-Za-z0-9_]{8}(?:\.[^./]*)?")


def user_path(name) -> str:
    """The path a user knows for a path we were writing: a temporary file of
    :func:`generator.atomic.atomic_path` becomes its destination, anything inside a stage of
    :func:`generator.atomic.staging` becomes the output folder the stage is in."""
    text = os.fsdecode(name) if isinstance(name, (bytes, os.PathLike)) else str(name)
    parts = text.split(os.sep)
    for i, part in enumerate(parts):
        if part.startswith(TMP_PREFIX):
            m = _ATOMIC_TMP.fullmatch(part) if i == len(parts) - 1 else None
            if m:
                return os.sep.join(parts[:i] + [m.group(1)])
            return os.sep.join(parts[:i]) or (os.sep if parts[:i] == [""] else ".")
    return text


def describe_os_error(e: OSError) -> str:
    """``<path>: <reason>`` (or ``<path> -> <path2>: <reason>``) for an OSError, escaped, one line."""
    names = list(dict.fromkeys(printable(user_path(n), 300) for n in (e.filename, e.filename2) if n not in (None, "")))
    where = " -> ".join(names)
    return f"{where}: {os_reason(e)}" if where else os_reason(e)


def _fail(flag: str, path, reason: str):
    head = f"{flag}: " if flag else ""
    raise UserError(f"{head}{printable(path, 300)}: {reason}")


def _stat(path: Path, flag: str) -> os.stat_result | None:
    """``os.stat`` (links followed); None when nothing is there; a one-line error for loops and the like."""
    try:
        return os.stat(path)
    except FileNotFoundError:
        return None
    except (OSError, ValueError) as e:
        if isinstance(e, OSError) and e.errno == errno.ENOTDIR:
            _fail(flag, path, "a part of the path is a file, not a folder")
        if isinstance(e, OSError) and e.errno == errno.ELOOP and os.path.islink(path):
            _fail(flag, path, os_reason(e))
        _fail(flag, path, os_reason(e) if isinstance(e, OSError) else "invalid path")


def input_dir(path: Path, flag: str = "", what: str = "folder") -> Path:
    """An existing folder to read (``what`` names it in the message: ``dataset folder``)."""
    st = _stat(path, flag)
    if st is None:
        _fail(flag, path, f"{what} not found")
    if not stat.S_ISDIR(st.st_mode):
        _fail(flag, path, f"is {file_kind(st.st_mode)}, expected a {what}")
    if not os.access(path, os.R_OK | os.X_OK):
        _fail(flag, path, "permission denied")
    return path


def input_file(path: Path, flag: str = "", what: str = "file") -> Path:
    """An existing regular file to read (``what`` names it in the message: ``predictions file``)."""
    st = _stat(path, flag)
    if st is None:
        _fail(flag, path, f"{what} not found")
    if not stat.S_ISREG(st.st_mode):
        _fail(flag, path, f"is {file_kind(st.st_mode)}, expected a {what}")
    if not os.access(path, os.R_OK):
        _fail(flag, path, "permission denied")
    return path


def _writable_ancestor(path: Path, flag: str) -> None:
    """The nearest existing ancestor of a path to be created: a writable folder; new names not too long."""
    for part in path.parts:
        if len(os.fsencode(part)) > NAME_MAX:
            _fail(flag, path, f"a file name in the path is longer than {NAME_MAX} bytes")
    parent = path.absolute().parent
    while True:
        st = _stat(parent, flag)
        if st is not None:
            break
        parent = parent.parent
    if not stat.S_ISDIR(st.st_mode):
        _fail(flag, path, f"{printable(parent, 200)} is {file_kind(st.st_mode)}, not a folder")
    if not os.access(parent, os.W_OK | os.X_OK):
        _fail(flag, path, f"cannot create it: {printable(parent, 200)} is not writable")


def _creatable(path: Path, flag: str, st) -> bool:
    """True when ``path`` does not exist yet (``st`` is None) and could be created; fails otherwise."""
    if st is not None:
        return False
    if os.path.islink(path):
        _fail(flag, path, "is a symbolic link to nothing")
    _writable_ancestor(path, flag)
    return True


def output_dir(path: Path, flag: str) -> Path:
    """A folder to write into: an existing writable folder, or a new one that can be created."""
    st = _stat(path, flag)
    if _creatable(path, flag, st):
        return path
    if not stat.S_ISDIR(st.st_mode):
        _fail(flag, path, f"exists and is {file_kind(st.st_mode)}, not a folder")
    if not os.access(path, os.W_OK | os.X_OK):
        _fail(flag, path, "folder is not writable")
    return path


def output_file(path: Path, flag: str) -> Path:
    """A file to (re)write: a regular file, or a new one whose folder exists or can be created."""
    st = _stat(path, flag)
    if _creatable(path, flag, st):
        return path
    if not stat.S_ISREG(st.st_mode):
        _fail(flag, path, f"exists and is {file_kind(st.st_mode)}; an output file must be a regular file or new")
    if not os.access(path.parent if str(path.parent) else Path("."), os.W_OK | os.X_OK):
        _fail(flag, path, "its folder is not writable")
    return path

