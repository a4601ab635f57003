"""Load JSON/YAML safely, validate against a JSON Schema, report one clear line.

Files are read through :mod:`generator.safeload`. Every problem becomes a
:class:`generator.errors.SpecError` whose message reads
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

from generator import safeload
from generator.errors import SpecError

SCHEMA_DIR = Path(__file__).resolve().parent / "schemas"


@functools.cache
def load_schema(name: str) -> dict:
    """The packaged JSON Schema ``schemas/<name>.schema.json``."""
    with open(SCHEMA_DIR / f"{name}.schema.json", encoding="utf-8") as f:
        return json.load(f)


def read_document(path: str | Path, source: str | None = None) -> Any:
    """Parse a JSON (``.json``) or YAML (other suffixes) file through :mod:`generator.safeload`.

    The file must be a regular UTF-8 file within the size limit; duplicate keys, NaN/inf,
    deep nesting and YAML alias bombs are refused.

    Parameters
    ----------
    path : path-like
        The file.
    source : str, optional
        How to name the file in messages (default: ``path`` as given).

    Raises
    ------
    SpecError
        Missing/unreadable/special file, or malformed content (with line and column, never
        quoting the file), or a non-finite number (naming its field).
    """
    source = str(path) if source is None else source
    if Path(path).suffix.lower() == ".json":
        return safeload.load_json(path, source=source)
    return safeload.load_yaml(path, source=source)


def _field_path(parts) -> str:
    # Keys come from the user's file: escaped and shortened so the message stays one line.
    return safeload.field_path(parts)


def _value(v: Any) -> str:
    if isinstance(v, str):
        return json.dumps(v) if len(v) < 80 else json.dumps(v[:77] + "...")
    text = json.dumps(v, default=str)
    return text if len(text) <= 80 else text[:77] + "..."


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
    elif t == "array" and ("minItems" in schema or schema.get("uniqueItems")):
        words = f"a list of at least {schema.get('minItems', 0)} items, each {describe(schema.get('items', {}))}"
        if schema.get("uniqueItems"):
            words += ", none repeated"
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
    if err.validator in ("minItems", "maxItems", "uniqueItems") and isinstance(err.instance, list):
        return _field_path(path), f"must be {describe(_resolve(err.schema, root))}, got {_value(err.instance)}"
    schema = _resolve(err.schema, root)
    if err.validator == "minProperties":
        return _field_path(
            path
        ), f"must name at least one of {', '.join(sorted(schema.get('properties', {})))}, got {{}}"
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


def _is_object(schema: dict) -> bool:
    t = schema.get("type")
    return t == "object" or (isinstance(t, list) and "object" in t)


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
        if key in out and isinstance(out[key], dict) and _is_object(sub):
            out[key] = with_defaults(out[key], sub, root)
    return out


def check_ranges(document: Any, source: str, path: tuple = ()) -> None:
    """Every ``[low, high]`` pair under a key ending in ``_m``/``_deg``/``_mmh`` or a known range must have
    low <= high."""
    if isinstance(document, dict):
        for k, v in document.items():
            check_ranges(v, source, path + (k,))
    elif (isinstance(document, list) and len(document) == 2 and all(isinstance(x, (int, float)) for x in document)
          and path and not path[-1].endswith(("xyz_m", "rpy_deg", "resolution"))):
        lo, hi = document
        if not (math.isfinite(lo) and math.isfinite(hi)) or lo > hi:
            raise SpecError(
                source, _field_path(path), f"must be a range [low, high] with low <= high, got {_value(document)}"
            )
