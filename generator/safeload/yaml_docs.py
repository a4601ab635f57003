"""YAML user documents: the safe loader with duplicate keys refused and depth, alias and node budgets."""

from __future__ import annotations

import os
from typing import Any

import yaml

# --------------------------------------------------------------------------- parsed data
from generator.safeload.documents import _clean, check_finite
from generator.safeload.files import read_text
from generator.safeload.limits import (
    MAX_ALIASES,
    MAX_DEPTH,
    MAX_INT_DIGITS,
    MAX_NODES,
    MAX_YAML_BYTES,
)
from generator.safeload.messages import (
    _fail,
    printable,
)

# --------------------------------------------------------------------------- YAML

#: libyaml's parser where PyYAML was built with it: the same documents, about six times faster
_PACKAGE_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


def load_package_yaml(stream) -> Any:
    """A YAML data file of the package itself (trusted, not a user's document): ``yaml.safe_load``'s
    result, parsed by libyaml when PyYAML has it (every process that builds a town reads half a dozen)."""
    return yaml.load(stream, Loader=_PACKAGE_LOADER)  # noqa: S506 - a safe loader


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


