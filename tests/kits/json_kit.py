"""JSON documents in hostile-input tests: every path to a value, and setting one."""

from __future__ import annotations


def value_paths(doc, prefix: tuple = (), max_items: int | None = None) -> list[tuple]:
    """Every path to a value in ``doc`` (mapping keys and list indices), parents before children.

    ``max_items``: visit only that many items of each list (long arrays of numbers add nothing).
    """
    out = [prefix] if prefix else []
    if isinstance(doc, dict):
        for k, v in doc.items():
            out += value_paths(v, prefix + (k,), max_items)
    elif isinstance(doc, list):
        for i, v in enumerate(doc[:max_items]):
            out += value_paths(v, prefix + (i,), max_items)
    return out
