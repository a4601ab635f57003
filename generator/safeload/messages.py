"""One-line messages: file names as the user gave them, escaped; reasons without content."""

from __future__ import annotations

import errno
import stat
from typing import NoReturn

from generator.errors import SpecError
from generator.safeload.limits import (
    KiB,
    MiB,
)

# --------------------------------------------------------------------------- messages


def printable(text: object, limit: int | None = None) -> str:
    """``text`` with control and other non-printable characters escaped, optionally shortened.

    Parameters
    ----------
    text : object
        A file name, field name or similar; converted with :class:`str`.
    limit : int, optional
        Keep at most this many characters (``...`` marks a cut).

    Returns
    -------
    str
        One line, safe to print on any terminal encoding (lone surrogates are escaped).
    """
    try:
        s = str(text)
    except ValueError:  # an integer too long to print
        s = "<a very long integer>"
    if not s.isprintable():
        s = "".join(c if c.isprintable() else c.encode("unicode_escape", "backslashreplace").decode("ascii")
                    for c in s)
    if limit is not None and len(s) > limit:
        s = s[: max(limit - 3, 0)] + "..."
    return s


def field_path(parts, prefix: str = "") -> str:
    """Dotted field path of ``parts``: ``town.blocks_x``, ``lasers[3].ring``.

    Parameters
    ----------
    parts : iterable of str or int
        Mapping keys (escaped with :func:`printable`, at most 64 characters) and list indices.
    prefix : str, optional
        Path the result continues.

    Returns
    -------
    str
        The path; empty for no parts and no prefix.
    """
    out = prefix
    for p in parts:
        if isinstance(p, int) and not isinstance(p, bool):
            out += f"[{p}]"
        else:
            key = printable(p, 64)
            out += f".{key}" if out else key
    return out


def _fail(source: object, field: str, reason: str) -> NoReturn:
    raise SpecError(printable(source), printable(field), reason)


def _size(n: int) -> str:
    if n >= MiB:
        return f"{n / MiB:.1f} MiB"
    if n >= KiB:
        return f"{n / KiB:.1f} KiB"
    return f"{n} bytes"


_OS_REASONS = {
    errno.ENOENT: "file not found",
    errno.ENOTDIR: "file not found (a part of the path is not a folder)",
    errno.ELOOP: "too many levels of symbolic links (a symlink loop)",
    errno.EACCES: "permission denied",
    errno.EPERM: "permission denied",
    errno.ENAMETOOLONG: "path too long",
    errno.EISDIR: "is a directory, expected a file",
}


def _os_reason(e: OSError) -> str:
    return _OS_REASONS.get(e.errno, f"cannot read ({e.strerror or type(e).__name__})")


def file_kind(mode: int) -> str:
    """What a ``st_mode`` is, in words for a message: ``a folder``, ``a file``, ``a named pipe (FIFO)``..."""
    for test, words in ((stat.S_ISDIR, "a folder"), (stat.S_ISREG, "a file"), (stat.S_ISFIFO, "a named pipe (FIFO)"),
                        (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
                        (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return words
    return "not a regular file"


def _kind_problem(mode: int) -> str | None:
    """None for a regular file, else why it cannot be read as one."""
    return None if stat.S_ISREG(mode) else f"is {file_kind(mode)}, expected a regular file"


