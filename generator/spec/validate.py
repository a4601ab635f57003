"""Load JSON/YAML safely, validate against a JSON Schema, report one clear line.

Every problem becomes a :class:`generator.errors.SpecError` whose message reads
``<file>: <field.path>: <reason>, got <value>``. Defaults declared in the schema are
filled in after validation, so the schema is the single place defaults live.
"""

from __future__ import annotations

import copy
import functools
import json
import math
from pathlib import Path
from typing import Any

import jsonschema
import yaml

from generator.errors import SpecError

SCHEMA_DIR = Path(__file__).resolve().parent / "schemas"


@functools.cache
def load_schema(name: str) -> dict:
    """The packaged JSON Schema ``schemas/<name>.schema.json``."""
    with open(SCHEMA_DIR / f"{name}.schema.json", "r", encoding="utf-8") as f:
        return json.load(f)


def _no_duplicates(pairs: list[tuple[str, Any]]) -> dict:
    out: dict = {}
    for k, v in pairs:
        if k in out:
            raise ValueError(f"duplicate key {k!r}")
        out[k] = v
    return out


def _reject_constant(name: str) -> None:
    raise ValueError(f"{name} is not a valid JSON number")


def read_document(path: str | Path, source: str | None = None) -> Any:
    """Parse a JSON (``.json``) or YAML (other suffixes) file safely.

    Parameters
    ----------
    path : path-like
        The file.
    source : str, optional
        How to name the file in messages (default: ``path`` as given).

    Raises
    ------
    SpecError
        Missing/unreadable file, or malformed content (with line and column).
    """
    source = str(path) if source is None else source
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise SpecError(source, "", "file not found") from None
    except IsADirectoryError:
        raise SpecError(source, "", "is a directory, expected a file") from None
    except (OSError, UnicodeDecodeError) as e:
        raise SpecError(source, "", f"cannot read: {e}") from None
    if p.suffix.lower() == ".json":
        try:
            return json.loads(text, object_pairs_hook=_no_duplicates, parse_constant=_reject_constant)
        except json.JSONDecodeError as e:
            raise SpecError(source, "", f"invalid JSON at line {e.lineno} column {e.colno}: {e.msg}") from None
        except ValueError as e:
            raise SpecError(source, "", f"invalid JSON: {e}") from None
    try:
        return yaml.safe_load(text)
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None)
        where = f" at line {mark.line + 1} column {mark.column + 1}" if mark else ""
        problem = getattr(e, "problem", None) or str(e).splitlines()[0]
        raise SpecError(source, "", f"invalid YAML{where}: {problem}") from None


def _field_path(parts) -> str:
    out = ""
    for p in parts:
        out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else str(p))
    return out


def _value(v: Any) -> str:
    return json.dumps(v) if not isinstance(v, str) or len(v) < 80 else json.dumps(v[:77] + "...")


_TYPE_WORDS = {"integer": "an integer", "number": "a number", "string": "a string", "boolean": "true or false",
               "object": "an object", "array": "a list", "null": "null"}


def describe(schema: dict) -> str:
    """Say in words what a schema accepts: ``an integer >= 1``, ``a number in [0, 1]``..."""
    if "enum" in schema:
        return "one of " + ", ".join(_value(v) for v in schema["enum"])
    t = schema.get("type")
    if isinstance(t, list):
        words = " or ".join(_TYPE_WORDS.get(x, x) for x in t)
    else:
        words = _TYPE_WORDS.get(t, "a value")
    lo, hi = schema.get("minimum"), schema.get("maximum")
    xlo, xhi = schema.get("exclusiveMinimum"), schema.get("exclusiveMaximum")
    low = (f"[{lo}", lo) if lo is not None else ((f"({xlo}", xlo) if xlo is not None else None)
    high = (f"{hi}]", hi) if hi is not None else ((f"{xhi})", xhi) if xhi is not None else None)
    if low and high:
        words += f" in {low[0]}, {high[0]}"
    elif low:
        words += (" >= " if lo is not None else " > ") + str(low[1])
    elif high:
        words += (" <= " if hi is not None else " < ") + str(high[1])
    if t == "array" and "minItems" in schema and schema.get("minItems") == schema.get("maxItems"):
        item = describe(schema.get("items", {}))
        words = f"a list of {schema['minItems']} items, each {item}"
    if "pattern" in schema:
        words += f" matching {schema['pattern']}"
    return words


def _resolve(schema: dict, root: dict) -> dict:
    while "$ref" in schema:
        ref = schema["$ref"]
        node = root
        for part in ref.lstrip("#/").split("/"):
            node = node[part]
        merged = {k: v for k, v in schema.items() if k != "$ref"}
        schema = {**node, **merged}
    return schema


def _message(err: jsonschema.ValidationError, root: dict) -> tuple[str, str]:
    path = list(err.absolute_path)
    if err.validator == "additionalProperties":
        extra = sorted(set(err.instance) - set(err.schema.get("properties", {})))
        allowed = ", ".join(sorted(err.schema.get("properties", {})))
        return _field_path(path + [extra[0]]), f"unknown key (allowed here: {allowed})"
    if err.validator == "required":
        missing = err.message.split("'")[1]
        return _field_path(path + [missing]), "is required"
    if err.validator in ("minItems", "maxItems") and isinstance(err.instance, list):
        return _field_path(path), f"must be {describe(_resolve(err.schema, root))}, got {_value(err.instance)}"
    schema = _resolve(err.schema, root)
    if err.validator == "type" and schema.get("type") == "object":
        return _field_path(path), f"must be an object, got {_value(err.instance)}"
    return _field_path(path), f"must be {describe(schema)}, got {_value(err.instance)}"


def validate(document: Any, schema: dict, source: str) -> None:
    """Validate ``document`` against ``schema``; raise the first (deepest) problem as a SpecError."""
    validator = jsonschema.Draft202012Validator(schema)
    errors = list(validator.iter_errors(document))
    if not errors:
        return
    # The most specific error: deepest path first, then a stable order.
    err = sorted(errors, key=lambda e: (-len(e.absolute_path), [str(p) for p in e.absolute_path], e.validator))[0]
    if err.validator in ("anyOf", "oneOf") and err.context:
        err = sorted(err.context, key=lambda e: -len(e.absolute_path))[0]
    field, reason = _message(err, schema)
    raise SpecError(source, field or "(top level)", reason)


def with_defaults(document: dict, schema: dict, root: dict | None = None) -> dict:
    """Return a deep copy of ``document`` with every omitted key filled from the schema defaults."""
    root = schema if root is None else root
    schema = _resolve(schema, root)
    out = copy.deepcopy(document)
    for key, sub in schema.get("properties", {}).items():
        sub = _resolve(sub, root)
        if key not in out:
            if "default" in sub:
                out[key] = copy.deepcopy(sub["default"])
            elif sub.get("type") == "object":
                out[key] = {}
        if key in out and isinstance(out[key], dict) and sub.get("type") == "object":
            out[key] = with_defaults(out[key], sub, root)
    return out


def check_ranges(document: Any, source: str, path: tuple = ()) -> None:
    """Every ``[low, high]`` pair under a key ending in ``_m``/``_deg``/``_mmh`` or a known range must have low <= high."""
    if isinstance(document, dict):
        for k, v in document.items():
            check_ranges(v, source, path + (k,))
    elif (isinstance(document, list) and len(document) == 2 and all(isinstance(x, (int, float)) for x in document)
          and path and not path[-1].endswith(("xyz_m", "rpy_deg", "resolution"))):
        lo, hi = document
        if not (math.isfinite(lo) and math.isfinite(hi)) or lo > hi:
            raise SpecError(source, _field_path(path), f"must be a range [low, high] with low <= high, got {_value(document)}")
