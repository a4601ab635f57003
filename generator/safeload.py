"""One hardened loading layer for every file a user hands to urbangen.

Specs, render configs, sensor and profile YAML, label configs, metadata JSON, pose and
calibration tables and binary scans all come from outside; a wrong, corrupted or hostile
file must end in one :class:`generator.errors.UserError` line ``<file>: <field>: <reason>``
(exit 2), quickly, without reading the whole of an endless input and without echoing the
file's content. Every reader of user files goes through this module; it is the bottom
layer and imports nothing else of urbangen but :mod:`generator.errors`.

What every file gets
--------------------
* **Regular files only**, checked with :func:`os.stat` before opening and again on the
  open descriptor (opened with ``O_NONBLOCK``, so a FIFO swapped in meanwhile cannot
  block): directories, FIFOs, sockets and devices (``/dev/zero``) are refused.
* **Size limit before reading**; at most ``max_bytes + 1`` bytes are read, so a file that
  grows (or a ``/proc`` file that claims size 0) is still caught.
* Symlink loops, permission problems, NUL bytes in paths: one line each.

Text and documents
------------------
* Strict UTF-8 (a leading byte-order mark is dropped); the message gives the byte offset.
* JSON: duplicate keys, ``NaN``/``Infinity`` and nesting deeper than :data:`MAX_DEPTH`
  are refused; the depth is measured on the text before parsing, so no parser recursion.
* YAML: the safe loader plus duplicate keys refused, aliases limited to
  :data:`MAX_ALIASES` and the expanded document to :data:`MAX_NODES` nodes ("billion
  laughs" fails at once), nesting limited (also through aliases), recursive aliases,
  ``!!binary``/``!!set``/``!!omap``/``!!pairs`` refused, dates kept as strings, keys must be
  strings unless asked otherwise. Errors read ``line L column C: <problem>`` with any
  quoted text of the parser's problem removed: the file's content never appears.
* Parsed data: every float finite, every integer within the float range
  (:func:`check_finite`, which names the field).

Messages
--------
The file is named as the user named it (``source``); control characters in names are
escaped so the message stays one line. Reasons never quote the content of the file.
"""

from __future__ import annotations

import errno
import json
import math
import os
import re
import stat
from pathlib import Path
from typing import Any, NoReturn

import numpy as np
import yaml

from generator.errors import SpecError

KiB = 1024
MiB = 1024 * KiB
GiB = 1024 * MiB

#: JSON specs and small JSON documents.
MAX_DOCUMENT_BYTES = 4 * MiB
#: YAML files (configs, sensors, profiles, label configs). Lower than JSON because the
#: pure-Python YAML parser (needed for the checks below) reads only ~0.2 MiB/s.
MAX_YAML_BYTES = 1 * MiB
#: Dataset metadata JSON (per image, per sequence, OpenLABEL).
MAX_METADATA_BYTES = 16 * MiB
#: Numeric text tables (poses, times, calibration).
MAX_TABLE_BYTES = 64 * MiB
#: Binary arrays (scans, labels).
MAX_ARRAY_BYTES = 1 * GiB
#: Deepest nesting of lists/mappings in a JSON or YAML document (top level = 1).
MAX_DEPTH = 64
#: YAML alias (``*name``) uses per document.
MAX_ALIASES = 100
#: Values per JSON/YAML document (containers, keys and scalars; YAML aliases counted
#: expanded). The largest shipped file has ~1000; pass more for dataset metadata.
MAX_NODES = 20_000
#: Longest integer literal (digits) accepted before it is even converted.
MAX_INT_DIGITS = 4000

_FLOAT_MAX = float(np.finfo(np.float64).max)

__all__ = [
    "MAX_ALIASES", "MAX_ARRAY_BYTES", "MAX_DEPTH", "MAX_DOCUMENT_BYTES", "MAX_INT_DIGITS", "MAX_METADATA_BYTES",
    "MAX_NODES", "MAX_TABLE_BYTES", "MAX_YAML_BYTES",
    "check_finite", "confined_path", "field_path", "load_json", "load_yaml", "parse_json", "parse_yaml",
    "printable", "read_array", "read_bytes", "read_matrix_rows", "read_text",
]


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


def _kind_problem(mode: int) -> str | None:
    if stat.S_ISREG(mode):
        return None
    if stat.S_ISDIR(mode):
        return "is a directory, expected a file"
    if stat.S_ISFIFO(mode):
        return "is a named pipe (FIFO), expected a regular file"
    if stat.S_ISCHR(mode):
        return "is a character device, expected a regular file"
    if stat.S_ISBLK(mode):
        return "is a block device, expected a regular file"
    if stat.S_ISSOCK(mode):
        return "is a socket, expected a regular file"
    return "is not a regular file"


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


# --------------------------------------------------------------------------- parsed data


def check_finite(obj: Any, source: str, field: str = "", *, max_depth: int | None = None,
                 max_nodes: int | None = None) -> None:
    """Refuse non-finite floats and integers beyond the float range anywhere in parsed data.

    Walks lists, tuples and mappings without recursion; shared sub-objects are visited once
    (so cyclic data terminates).

    Parameters
    ----------
    obj : object
        Parsed JSON/YAML data.
    source : str
        The file it came from, for messages.
    field : str, optional
        Field path of ``obj`` itself (prefix of the paths reported).
    max_depth : int, optional
        Also refuse nesting deeper than this (top-level container = 1).
    max_nodes : int, optional
        Also refuse more values than this (every container, key and scalar counts one).

    Raises
    ------
    generator.errors.SpecError
        ``<file>: <field.path>: must be a finite number, got nan``, too deep, or too many values.
    """
    # A path is a linked list (parent_path, key), so extending it is O(1) however deep the data.
    stack: list[tuple[Any, tuple | None, int]] = [(obj, None, 0)]
    seen: set[int] = set()
    nodes = 0

    def where(path) -> str:
        parts = []
        while path is not None:
            path, key = path
            parts.append(key)
        return field_path(reversed(parts), field) or "(top level)"

    while stack:
        node, path, depth = stack.pop()
        nodes += 1
        if max_nodes is not None and nodes > max_nodes:
            _fail(source, field, f"more than {max_nodes} values (lists, mappings, keys and scalars)")
        if isinstance(node, bool) or node is None or isinstance(node, str):
            continue
        if isinstance(node, (float, np.floating)):
            if not math.isfinite(node):
                _fail(source, where(path), f"must be a finite number, got {float(node)}")
        elif isinstance(node, (int, np.integer)):
            if abs(int(node)) > _FLOAT_MAX:
                digits = int((int(node).bit_length() - 1) * math.log10(2)) + 1  # str() refuses > 4300 digits
                _fail(source, where(path), f"must be a finite number, got an integer with about {digits} digits")
        elif isinstance(node, (dict, list, tuple)):
            if id(node) in seen:
                continue
            seen.add(id(node))
            if max_depth is not None and depth + 1 > max_depth:
                _fail(source, where(path), f"nested deeper than {max_depth} levels")
            if isinstance(node, dict):
                nodes += len(node)  # the keys
                items = node.items()
            else:
                items = enumerate(node)
            stack.extend((v, (path, k), depth + 1) for k, v in reversed(list(items)))


# --------------------------------------------------------------------------- JSON

# A string, or an unterminated one up to the end: possessive, so every match succeeds
# where it starts and the scan stays linear (no retry from each later quote).
_JSON_STRING = re.compile(r'"(?:[^"\\]|\\.)*+(?:"|\\?\Z)', re.DOTALL)
_NOT_BRACKET = re.compile(r"[^\[\]{}]+")


def _json_depth(text: str) -> int:
    """Deepest bracket nesting of JSON text (strings skipped), without parsing it."""
    brackets = _NOT_BRACKET.sub("", _JSON_STRING.sub("", text))
    if not brackets:
        return 0
    codes = np.frombuffer(brackets.encode("ascii"), np.uint8)
    return int(np.cumsum(np.where((codes == ord("[")) | (codes == ord("{")), 1, -1), dtype=np.int64).max())


def _json_object(pairs: list[tuple[str, Any]]) -> dict:
    out: dict = {}
    for k, v in pairs:
        if k in out:
            raise ValueError(f"duplicate key {printable(k, 64)!r}")
        out[k] = v
    return out


def _json_constant(name: str) -> None:
    raise ValueError(f"{name} is not a valid JSON number")


def _json_int(text: str) -> int | float:
    # Beyond this many digits int() itself refuses (and is slow); the number is out of range anyway.
    return int(text) if len(text) <= MAX_INT_DIGITS else math.inf


def _clean(problem: str) -> str:
    """A parser's problem text with quoted content removed (a single quoted character or a
    ``'<token>'`` name is kept: they say what was expected, not what the file holds)."""
    def keep(m: re.Match) -> str:
        inner = m.group(0)[1:-1]
        q = m.group(0)[0]
        return m.group(0) if len(inner) <= 2 or re.fullmatch(r"<[a-z ]+>", inner) else f"{q}...{q}"
    return printable(re.sub(r"'[^'\n]*'|\"[^\"\n]*\"", keep, problem), 200)


def parse_json(text: str, source: str, *, field: str = "", max_depth: int = MAX_DEPTH,
               max_nodes: int = MAX_NODES) -> Any:
    """Parse JSON text strictly.

    Parameters
    ----------
    text : str
        The document.
    source : str
        The file it came from, for messages.
    field : str, optional
        Field path prefix for messages.
    max_depth : int, optional
        Deepest nesting allowed (top-level container = 1).
    max_nodes : int, optional
        Most values allowed (containers, keys and scalars).

    Returns
    -------
    object
        The data; every number finite.

    Raises
    ------
    generator.errors.SpecError
        ``invalid JSON at line L column C: <problem>``, duplicate keys, NaN/Infinity,
        too deep, or a number out of range (naming its field).
    """
    if _json_depth(text) > max_depth:
        _fail(source, field, f"invalid JSON: nested deeper than {max_depth} levels")
    try:
        data = json.loads(text, object_pairs_hook=_json_object, parse_constant=_json_constant, parse_int=_json_int)
    except json.JSONDecodeError as e:
        _fail(source, field, f"invalid JSON at line {e.lineno} column {e.colno}: {_clean(e.msg)}")
    except RecursionError:
        _fail(source, field, f"invalid JSON: nested deeper than {max_depth} levels")
    except ValueError as e:
        _fail(source, field, f"invalid JSON: {e}")
    check_finite(data, source, field, max_depth=max_depth, max_nodes=max_nodes)
    return data


def load_json(path: str | os.PathLike, *, source: str | None = None, field: str = "",
              max_bytes: int = MAX_DOCUMENT_BYTES, max_depth: int = MAX_DEPTH, max_nodes: int = MAX_NODES) -> Any:
    """Read and parse a JSON file with every check of :func:`read_text` and :func:`parse_json`.

    Parameters
    ----------
    path : path-like
        The file.
    source : str, optional
        How to name the file in messages (default: ``path`` as given).
    field : str, optional
        Field that named the file, if any.
    max_bytes : int, optional
        Size limit (use :data:`MAX_METADATA_BYTES` for dataset metadata).
    max_depth, max_nodes : int, optional
        Deepest nesting and most values allowed (see :func:`parse_json`).

    Returns
    -------
    object
        The data.

    Raises
    ------
    generator.errors.SpecError
        Any problem, as one line.
    """
    src = str(path) if source is None else source
    return parse_json(read_text(path, source=src, field=field, max_bytes=max_bytes), src, field=field,
                      max_depth=max_depth, max_nodes=max_nodes)


# --------------------------------------------------------------------------- YAML


class _Refused(yaml.MarkedYAMLError):
    def __init__(self, problem: str, mark):
        super().__init__(problem=problem, problem_mark=mark)


class _SafeLoader(yaml.SafeLoader):
    """PyYAML's safe loader with budgets (depth, aliases, expanded nodes) and strict mappings."""

    max_depth = MAX_DEPTH
    max_aliases = MAX_ALIASES
    max_nodes = MAX_NODES
    string_keys = True

    def __init__(self, stream):
        super().__init__(stream)
        self._depth = 0
        self._aliases = 0
        self._expanded = 0
        self._size: dict[int, tuple[int, int]] = {}  # id(node) -> (expanded nodes, height)

    def compose_node(self, parent, index):
        if self.check_event(yaml.AliasEvent):
            mark = self.peek_event().start_mark
            self._aliases += 1
            if self._aliases > self.max_aliases:
                raise _Refused(f"more than {self.max_aliases} aliases", mark)
            node = super().compose_node(parent, index)
            size = self._size.get(id(node))
            if size is None:
                raise _Refused("recursive alias (refers to a node that contains it)", mark)
            self._count(size[0], mark)
            if self._depth + size[1] > self.max_depth:
                raise _Refused(f"nested deeper than {self.max_depth} levels (through an alias)", mark)
            return node
        mark = self.peek_event().start_mark
        self._count(1, mark)
        self._depth += 1
        if self._depth > self.max_depth:
            raise _Refused(f"nested deeper than {self.max_depth} levels", mark)
        try:
            node = super().compose_node(parent, index)
        finally:
            self._depth -= 1
        if isinstance(node, yaml.MappingNode):
            children = [n for pair in node.value for n in pair]
        elif isinstance(node, yaml.SequenceNode):
            children = node.value
        else:
            children = []
        sizes = [self._size[id(c)] for c in children]
        self._size[id(node)] = (1 + sum(s[0] for s in sizes), 1 + max((s[1] for s in sizes), default=0))
        return node

    def _count(self, n: int, mark) -> None:
        self._expanded += n
        if self._expanded > self.max_nodes:
            raise _Refused(f"more than {self.max_nodes} values (aliases expanded)", mark)

    def construct_mapping(self, node, deep=False):
        if isinstance(node, yaml.MappingNode):
            seen = set()
            for key_node, _ in node.value:
                if key_node.tag == "tag:yaml.org,2002:merge":
                    continue
                key = self.construct_object(key_node, deep=deep)
                if self.string_keys and not isinstance(key, str):
                    raise _Refused(f"a key must be a string, got {type(key).__name__} (quote the key)",
                                   key_node.start_mark)
                try:
                    duplicate = key in seen
                except TypeError:
                    raise _Refused("found unhashable key", key_node.start_mark) from None
                if duplicate:
                    raise _Refused(f"duplicate key {printable(key, 64)!r}", key_node.start_mark)
                seen.add(key)
        return super().construct_mapping(node, deep=deep)

    def construct_yaml_int(self, node):
        if len(node.value) > MAX_INT_DIGITS:
            raise _Refused(f"integer with more than {MAX_INT_DIGITS} digits", node.start_mark)
        return super().construct_yaml_int(node)

    def construct_yaml_float(self, node):
        if len(node.value) > MAX_INT_DIGITS:
            raise _Refused(f"number with more than {MAX_INT_DIGITS} digits", node.start_mark)
        return super().construct_yaml_float(node)

    def _refuse_tag(self, node):
        raise _Refused(f"unsupported tag {node.tag.rsplit(':', 1)[-1]!r} (only plain JSON-like data is read)",
                       node.start_mark)


_SafeLoader.add_constructor("tag:yaml.org,2002:int", _SafeLoader.construct_yaml_int)
_SafeLoader.add_constructor("tag:yaml.org,2002:float", _SafeLoader.construct_yaml_float)
for _tag in ("binary", "set", "omap", "pairs", "timestamp"):
    _SafeLoader.add_constructor(f"tag:yaml.org,2002:{_tag}", _SafeLoader._refuse_tag)
# Dates stay strings (as in JSON): no implicit timestamp resolution.
_SafeLoader.yaml_implicit_resolvers = {
    first: [(tag, rx) for tag, rx in resolvers if tag != "tag:yaml.org,2002:timestamp"]
    for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
}


def _yaml_reason(e: yaml.YAMLError, text: str) -> str:
    if isinstance(e, yaml.reader.ReaderError):
        line = text.count("\n", 0, e.position) + 1
        column = e.position - (text.rfind("\n", 0, e.position) + 1) + 1
        return f"invalid YAML at line {line} column {column}: unacceptable character #x{e.character:04x}"
    mark = getattr(e, "problem_mark", None) or getattr(e, "context_mark", None)
    problem = getattr(e, "problem", None) or getattr(e, "context", None) or "cannot be parsed"
    where = f" at line {mark.line + 1} column {mark.column + 1}" if mark is not None else ""
    if problem.startswith("but ") and getattr(e, "context", None):
        problem = f"{e.context}, {problem}"  # "expected a single document in the stream, but found another"
    # Our own refusals word their problem themselves; the parser's may quote the file.
    return f"invalid YAML{where}: {problem if isinstance(e, _Refused) else _clean(problem)}"


def parse_yaml(text: str, source: str, *, field: str = "", max_depth: int = MAX_DEPTH,
               max_aliases: int = MAX_ALIASES, max_nodes: int = MAX_NODES, string_keys: bool = True) -> Any:
    """Parse one YAML document safely and strictly.

    Parameters
    ----------
    text : str
        The document.
    source : str
        The file it came from, for messages.
    field : str, optional
        Field path prefix for messages.
    max_depth, max_aliases, max_nodes : int, optional
        Budgets: nesting depth (also through aliases), alias uses, nodes with aliases expanded.
    string_keys : bool, optional
        Require every mapping key to be a string (as in JSON); label tables keyed by
        numbers pass False.

    Returns
    -------
    object
        The data (plain dicts, lists, strings, numbers, booleans, None); every number finite.

    Raises
    ------
    generator.errors.SpecError
        ``invalid YAML at line L column C: <problem>`` (never quoting the file), or a
        non-finite number naming its field.
    """
    loader_cls = type("_Loader", (_SafeLoader,), {"max_depth": max_depth, "max_aliases": max_aliases,
                                                  "max_nodes": max_nodes, "string_keys": string_keys})
    loader = None
    try:
        loader = loader_cls(text)  # the reader checks for unprintable characters here
        data = loader.get_single_data()
    except yaml.YAMLError as e:
        _fail(source, field, _yaml_reason(e, text))
    except RecursionError:
        _fail(source, field, f"invalid YAML: nested deeper than {max_depth} levels")
    except (ValueError, TypeError, OverflowError) as e:  # a constructor choking on a value
        _fail(source, field, f"invalid YAML: cannot be read ({type(e).__name__})")
    finally:
        if loader is not None:
            loader.dispose()
    check_finite(data, source, field, max_depth=max_depth)
    return data


def load_yaml(path: str | os.PathLike, *, source: str | None = None, field: str = "",
              max_bytes: int = MAX_YAML_BYTES, **budgets) -> Any:
    """Read and parse a YAML file with every check of :func:`read_text` and :func:`parse_yaml`.

    Parameters
    ----------
    path : path-like
        The file.
    source : str, optional
        How to name the file in messages (default: ``path`` as given).
    field : str, optional
        Field that named the file, if any.
    max_bytes : int, optional
        Size limit.
    **budgets
        ``max_depth``, ``max_aliases``, ``max_nodes``, ``string_keys`` for :func:`parse_yaml`.

    Returns
    -------
    object
        The data.

    Raises
    ------
    generator.errors.SpecError
        Any problem, as one line.
    """
    src = str(path) if source is None else source
    return parse_yaml(read_text(path, source=src, field=field, max_bytes=max_bytes), src, field=field, **budgets)


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
