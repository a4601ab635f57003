"""Reading dataset metadata JSON back: typed access to the fields the readers use.

Image metadata, a sequence's ``lidar_meta.json``, OpenLABEL files and the manifest come from
outside like any user file: they are read through :mod:`generator.safeload` (size limit,
strict JSON, finite numbers, bounded depth) by :func:`load_metadata`, and every field a
reader uses is fetched with :func:`field`, :func:`matrix` or :func:`integer`, which check its
type and shape and fail with one line ``<file>: <field.path>: <reason>`` that names what was
expected and what kind of value was found, never the value itself.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from generator import safeload
from generator.errors import SpecError

#: Values a dataset metadata JSON may hold (an image's has ~300; a sequence's ``lidar_meta.json``
#: and an OpenLABEL file grow with their frames). The byte limit is ``safeload.MAX_METADATA_BYTES``.
MAX_METADATA_NODES = 5_000_000
#: Farthest a world pose in metadata may be from the world origin, metres.
MAX_WORLD_M = 1e7
#: Largest image side a metadata file may declare.
MAX_IMAGE_SIDE = 65535
_REQUIRED = object()


def load_metadata(path: str | Path, source: str | None = None) -> dict:
    """A dataset metadata JSON file (image metadata, ``lidar_meta.json``, OpenLABEL, manifest).

    Read through :mod:`generator.safeload` with the metadata size limit: a regular UTF-8
    file, strict JSON, finite numbers, bounded depth; the top level must be an object.

    Raises
    ------
    generator.errors.SpecError
        One line ``<file>: <field>: <reason>``, never quoting the file.
    """
    src = str(path) if source is None else source
    doc = safeload.load_json(path, source=src, max_bytes=safeload.MAX_METADATA_BYTES, max_nodes=MAX_METADATA_NODES)
    if not isinstance(doc, dict):
        raise SpecError(src, "(top level)", f"must be a JSON object, got {kind_of(doc)}")
    return doc


def kind_of(value: Any) -> str:
    """``a string``, ``a list``... : what a JSON value is, without saying what it holds."""
    if isinstance(value, bool):
        return "true or false"
    if value is None:
        return "null"
    return {int: "an integer", float: "a number", str: "a string", list: "a list", dict: "an object"}.get(
        type(value), type(value).__name__)


def field(doc: dict, dotted: str, source: str, default: Any = _REQUIRED, prefix: str = "") -> Any:
    """The value at ``dotted`` (``camera.intrinsics.K``); ``default`` when absent, else an error.

    ``prefix`` is where ``doc`` itself sits in its file (``sweep_poses_world.frames[3]``), for messages.

    Raises
    ------
    generator.errors.SpecError
        ``<file>: <field>: is required`` or ``<file>: <parent>: must be an object, got a list``.
    """
    node, done = doc, [prefix] if prefix else []
    for key in dotted.split("."):
        if not isinstance(node, dict):
            raise SpecError(source, ".".join(done) or "(top level)", f"must be an object, got {kind_of(node)}")
        if key not in node:
            if default is _REQUIRED:
                raise SpecError(source, ".".join(done + [key]), "is required")
            return default
        node = node[key]
        done.append(key)
    return node


def matrix(doc: dict, dotted: str, shape: tuple[int, ...], source: str, default: Any = _REQUIRED,
           prefix: str = "") -> np.ndarray:
    """``field(doc, dotted)`` as a float64 array of exactly ``shape`` (nested lists of numbers; finite,
    as every number safeload parsed); ``-1`` in ``shape`` allows any length there."""
    value = field(doc, dotted, source, default, prefix)
    if value is default and default is not _REQUIRED:
        return value
    if not _is_numbers(value, shape):
        what = "x".join("n" if n < 0 else str(n) for n in shape)
        raise SpecError(
            source,
            ".".join(p for p in (prefix, dotted) if p),
            f"must be {'a list of ' + what if len(shape) == 1 else 'a ' + what + ' matrix'}"
            f" of numbers, got {kind_of(value)} of another shape or with non-numbers",
        )
    return np.array(value, np.float64).reshape(shape)


def _is_numbers(value: Any, shape: tuple[int, ...]) -> bool:
    if not shape:
        return isinstance(value, (int, float)) and not isinstance(value, bool)
    if not isinstance(value, list) or (shape[0] >= 0 and len(value) != shape[0]):
        return False
    return all(_is_numbers(v, shape[1:]) for v in value)


def integer(doc: dict, dotted: str, source: str, lo: int, hi: int, default: Any = _REQUIRED) -> int:
    """``field(doc, dotted)`` as an integer in ``[lo, hi]``."""
    value = field(doc, dotted, source, default)
    if value is default and default is not _REQUIRED:
        return value
    if not isinstance(value, int) or isinstance(value, bool) or not lo <= value <= hi:
        got = (
            f"{value}"
            if isinstance(value, int) and not isinstance(value, bool) and abs(value) < 10**12
            else kind_of(value)
        )
        raise SpecError(source, dotted, f"must be an integer in [{lo}, {hi}], got {got}")
    return value


def intrinsics(doc: dict, source: str) -> tuple[np.ndarray, int, int]:
    """(K (3, 3), width, height) of image metadata, checked: ``K = [[fx, s, cx], [0, fy, cy], [0, 0, 1]]``
    with focal lengths > 0 and an image of 1..:data:`MAX_IMAGE_SIDE` pixels a side."""
    K = matrix(doc, "camera.intrinsics.K", (3, 3), source)
    if not (K[0, 0] > 0 and K[1, 1] > 0 and K[1, 0] == 0 and np.array_equal(K[2], [0.0, 0.0, 1.0])):
        raise SpecError(source, "camera.intrinsics.K", "must be a pinhole matrix [[fx, s, cx], [0, fy, cy], [0, 0, 1]] "
                                                        "with fx, fy > 0")
    width = integer(doc, "camera.intrinsics.width", source, 1, MAX_IMAGE_SIDE)
    height = integer(doc, "camera.intrinsics.height", source, 1, MAX_IMAGE_SIDE)
    return K, width, height


def exr_path(doc: dict, meta_path: str | Path, source: str | None = None, must_exist: bool = True) -> Path:
    """The EXR an image's metadata names (``files.exr``), which must lie beside the metadata file.

    Raises
    ------
    generator.errors.SpecError
        Not a string, empty, absolute, leading out of the metadata's folder (``..``, a link),
        or (``must_exist``) naming nothing there. The name itself is never repeated: it is
        the file's content until it is known to name a file of the dataset.
    """
    src = str(meta_path) if source is None else source
    rel = field(doc, "files.exr", src)
    if not isinstance(rel, str) or not rel or "\0" in rel:
        raise SpecError(
            src,
            "files.exr",
            f"must be a file name, got {kind_of(rel) if not isinstance(rel, str) else 'an empty or invalid string'}",
        )
    base = os.path.realpath(Path(meta_path).parent)
    target = os.path.realpath(os.path.join(base, rel))
    if os.path.isabs(rel) or os.path.commonpath([base, target]) != base:
        raise SpecError(src, "files.exr", "must name a file in the metadata's own folder (no absolute path, "
                                          "no '..', no link leading out)")
    if must_exist and not os.path.lexists(os.path.join(base, rel)):
        raise SpecError(src, "files.exr", "names no file beside the metadata")
    return Path(meta_path).parent / rel


def schema_message(err) -> str:
    """One line for a ``jsonschema`` error that names the field and what the schema wants, never
    the offending value (``jsonschema``'s own messages quote it: file content in a message)."""
    where = safeload.field_path(err.absolute_path) or "(top level)"
    v, want = err.validator, err.validator_value
    if v == "required":  # names a property of the schema
        return f"{where}: {err.message}"
    if v == "type":
        kinds = " or ".join(want) if isinstance(want, list) else want
        return f"{where}: must be of type {kinds}, got {kind_of(err.instance)}"
    if v in ("enum", "const"):
        allowed = want if v == "enum" else [want]
        return (f"{where}: must be {'one of ' if v == 'enum' else ''}"
                f"{', '.join(safeload.printable(a, 40) for a in allowed[:12])}")
    if v == "additionalProperties" and isinstance(err.instance, dict):
        extra = sorted(set(err.instance) - set(err.schema.get("properties", {})))
        return f"{where}: unknown key {safeload.printable(extra[0] if extra else '?', 64)!r}"
    if v in ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum", "minItems", "maxItems",
             "minProperties", "maxProperties", "minLength", "maxLength", "pattern", "multipleOf"):
        return f"{where}: must satisfy {v} {safeload.printable(want, 80)}"
    if v in ("anyOf", "oneOf"):
        return f"{where}: matches none of the forms the schema allows"
    return f"{where}: does not satisfy the schema ({v})"


def sweep_poses(meta: dict, source: str) -> list[tuple[np.ndarray, np.ndarray]]:
    """``sweep_poses_world.frames`` of ``lidar_meta.json`` as (t_s (k,), T_world_lidar (k, 4, 4)) per scan.

    Checked at the border, since de-skewing interpolates them: at least one knot, times
    starting at 0 and strictly increasing, rigid poses.
    """
    frames = field(meta, "sweep_poses_world.frames", source, default=None)
    if frames is None:
        return []
    if not isinstance(frames, list):
        raise SpecError(source, "sweep_poses_world.frames", f"must be a list, got {kind_of(frames)}")
    out = []
    for i, f in enumerate(frames):
        where = f"sweep_poses_world.frames[{i}]"
        if not isinstance(f, dict):
            raise SpecError(source, where, f"must be an object, got {kind_of(f)}")
        t = matrix(f, "t_s", (-1,), source, prefix=where)
        poses = matrix(f, "T_world_lidar", (len(t), 4, 4), source, prefix=where)
        if len(t) < 1 or t[0] != 0 or (np.diff(t) <= 0).any():
            raise SpecError(source, f"{where}.t_s", "must start at 0 and increase strictly")
        for j, T in enumerate(poses):
            problem = rigid_problem(T)
            if problem:
                raise SpecError(source, f"{where}.T_world_lidar[{j}]", problem)
        out.append((t, poses))
    return out


def image_sweeps(meta: dict, source: str) -> dict[int, int]:
    """Image frame ``k`` -> the sweep ``j`` it was exposed with (``image_frames`` of ``lidar_meta.json``).

    Empty when the sequence has no ``image_frames`` (the older one-sweep-per-image layout, where
    image ``k`` is scan ``k``).

    Raises
    ------
    SpecError
        ``image_frames`` is not a list of ``[image frame, sweep]`` pairs of integers >= 0, one per
        image frame.
    """
    pairs = field(meta, "image_frames", source, default=[])
    if not isinstance(pairs, list) or not all(isinstance(p, list) and len(p) == 2 and all(
            isinstance(v, int) and not isinstance(v, bool) and v >= 0 for v in p) for p in pairs):
        raise SpecError(source, "image_frames", "must be a list of [image frame, sweep] pairs of integers >= 0")
    out = {k: j for k, j in pairs}
    if len(out) != len(pairs):
        raise SpecError(source, "image_frames", "an image frame is paired with more than one sweep")
    return out


def rigid_problem(T: np.ndarray, tol: float = 1e-3) -> str | None:
    """Why a (4, 4) world pose read from metadata is not rigid or is beyond :data:`MAX_WORLD_M`, or
    None (the rotation test of :func:`generator.formats.kitti_calib.rigid_problem`, which this layer
    cannot import)."""
    T = np.asarray(T, np.float64)
    r = T[:3, :3]
    if np.abs(r).max() > 1 + tol or np.abs(r @ r.T - np.eye(3)).max() > tol or abs(np.linalg.det(r) - 1.0) > tol:
        return "rotation part is not a rotation (not orthonormal with determinant +1)"
    if np.abs(T[:3, 3]).max() > MAX_WORLD_M or not np.array_equal(T[3], [0.0, 0.0, 0.0, 1.0]):
        return f"must be a rigid transform [[R, t], [0, 0, 0, 1]] with |t| within {MAX_WORLD_M:.0e} m"
    return None
