"""Parsed user documents: finite numbers everywhere, and JSON with depth and node budgets."""

from __future__ import annotations

import json
import math
import os
import re
from typing import Any

import numpy as np

from generator.safeload.files import read_text
from generator.safeload.limits import (
    _FLOAT_MAX,
    MAX_DEPTH,
    MAX_DOCUMENT_BYTES,
    MAX_INT_DIGITS,
    MAX_NODES,
)
from generator.safeload.messages import (
    _fail,
    field_path,
    printable,
)

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
