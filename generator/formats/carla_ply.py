"""KITTI-CARLA towns: binary PLY frames of CARLA's semantic LiDAR, their poses and tag map.

A KITTI-CARLA town (Deschaud 2021, CARLA 0.9.10) is laid out as::

    TownNN/generated/frames/frame_NNNN.ply     one 360-degree sweep per file
    TownNN/generated/full_poses_lidar.txt      one line per LiDAR packet (optional)

(``frames/`` and ``full_poses_lidar.txt`` directly under the town folder are accepted too.)

Frame vertices (binary little-endian PLY): ``float x, y, z`` (LiDAR frame at the packet's
time, metres, x forward, y left, z up -- KITTI's convention, not de-skewed),
``float cos_angle_lidar_surface`` (cosine of the incidence angle; ``cos`` accepted),
optional ``float timestamp`` (seconds, the packet's time), ``uint instance`` (CARLA object
index) and ``uint semantic`` (CARLA 0.9.10 tag 0..22).

``full_poses_lidar.txt``: a ``#`` comment line, then 13 numbers per line: the 3x4 row-major
pose ``[R | t]`` of the LiDAR in the frame of the first LiDAR pose, then the packet
timestamp (seconds). Frame ``i``'s pose is the packet pose at the sweep start: the line
whose timestamp equals the frame's smallest point timestamp, or -- without point
timestamps -- line ``i * (lines // frames)``. No pose file: identity poses.
"""

from __future__ import annotations

import functools
import math
import os
import re
from pathlib import Path
from typing import NoReturn

import numpy as np

from generator import safeload
from generator.errors import SpecError, UserError
from generator.formats.kitti_calib import rigid_problem
from generator.formats.semantickitti import MAX_POINT_M, MAX_TRANSLATION_M
from generator.labels import class_table
from generator.safeload import load_package_yaml

TAG_FILE = Path(__file__).resolve().with_name("carla_semantic_tags.yaml")
_PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2",
    "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}
_ALIASES = {"cos": ("cos_angle_lidar_surface", "cos", "CosAngle"), "semantic": ("semantic", "ObjTag", "tag"),
            "instance": ("instance", "ObjIdx"), "timestamp": ("timestamp",)}
#: Largest frame file read (a 360-degree sweep is a few MiB).
MAX_PLY_BYTES = safeload.MAX_ARRAY_BYTES
#: The header must end within this many bytes.
MAX_HEADER_BYTES = 64 * 1024
_END_HEADER = re.compile(rb"(?:^|\n)end_header\r?\n")
_COUNT = re.compile(r"[0-9]{1,12}")
#: What :func:`read_frame` returns per point.
FRAME_DTYPE = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("cos", "<f4"), ("timestamp", "<f8"),
                        ("instance", "<u4"), ("tag", "<u4")])


def _bad(path, reason: str) -> NoReturn:
    raise UserError(f"{safeload.printable(path)}: {reason}")


def _header_lines(data: bytes, path) -> tuple[list[str], int]:
    """(header lines after ``ply``, offset of the body) of PLY bytes."""
    if not data.startswith((b"ply\n", b"ply\r\n")):
        _bad(path, "not a PLY file")
    m = _END_HEADER.search(data, 0, MAX_HEADER_BYTES)
    if m is None:
        _bad(path, f"not a PLY file (no end_header line in the first {MAX_HEADER_BYTES // 1024} KiB)")
    try:
        header = data[: m.start()].decode("ascii")
    except UnicodeDecodeError as e:
        _bad(path, f"PLY header is not ASCII text (byte {e.start})")
    return header.splitlines()[1:], m.end()


def read_ply_vertices(path: str | Path) -> np.ndarray:
    """The ``vertex`` element of a binary PLY as a structured array (fields named as in the header).

    Read through :mod:`generator.safeload` (a regular file within :data:`MAX_PLY_BYTES`); the
    header is parsed strictly and never quoted in messages.

    Raises
    ------
    UserError
        Not a PLY, ASCII format, a malformed header line (a vertex count that is not a
        non-negative integer, list properties, unknown types, a property twice), or a size
        mismatch (naming the file).
    """
    path = Path(path)
    data = safeload.read_bytes(path, max_bytes=MAX_PLY_BYTES)
    lines, body_at = _header_lines(data, path)
    fmt, fields, n, current, elements = None, [], None, None, []
    for lineno, line in enumerate(lines, 2):
        words = line.split()
        where = f"PLY header line {lineno}"
        if not words or words[0] in ("comment", "obj_info"):
            continue
        if words[0] == "format":
            if len(words) != 3:
                _bad(path, f"{where}: expected 'format <binary_little_endian|binary_big_endian> 1.0'")
            fmt = words[1]
        elif words[0] == "element":
            if len(words) != 3 or not _COUNT.fullmatch(words[2]):
                _bad(path, f"{where}: expected 'element <name> <count>' with a count that is an integer >= 0")
            current = words[1]
            elements.append(current)
            if current == "vertex":
                n = int(words[2])
        elif words[0] == "property":
            if current is None:
                _bad(path, f"{where}: a property before any element")
            if current != "vertex":
                continue
            if len(words) != 3 or words[1] not in _PLY_TYPES:
                _bad(path, f"{where}: unsupported vertex property (only scalar {', '.join(sorted(set(_PLY_TYPES)))})")
            if any(name == words[2] for name, _ in fields):
                _bad(path, f"{where}: vertex property given twice")
            fields.append((words[2], _PLY_TYPES[words[1]]))
        else:
            _bad(path, f"{where}: unknown header keyword (expected format, element, property or comment)")
    if fmt not in ("binary_little_endian", "binary_big_endian"):
        shown = repr(fmt) if fmt in ("ascii", None) else "other than binary"
        _bad(path, f"PLY format {shown} not supported (binary_little_endian or binary_big_endian)")
    if n is None or elements[0] != "vertex":
        _bad(path, "the first PLY element must be 'vertex'")
    if not fields:
        _bad(path, "the vertex element has no properties")
    order = "<" if fmt == "binary_little_endian" else ">"
    dtype = np.dtype([(name, order + t) for name, t in fields])
    if len(data) - body_at < n * dtype.itemsize:
        _bad(path, f"{len(data) - body_at} bytes of vertex data for {n} vertices of {dtype.itemsize} bytes (truncated)")
    return np.frombuffer(data, dtype, count=n, offset=body_at)


def _field(v: np.ndarray, key: str, path: Path, required: bool = True):
    for name in _ALIASES.get(key, (key,)):
        if name in v.dtype.names:
            return v[name]
    if required:
        _bad(path, f"PLY has no '{_ALIASES.get(key, (key,))[0]}' property")
    return None


def read_frame(path: str | Path) -> np.ndarray:
    """One KITTI-CARLA frame as (n,) :data:`FRAME_DTYPE` (timestamp NaN when the PLY has none).

    Raises
    ------
    UserError
        A PLY problem (:func:`read_ply_vertices`), a missing property, non-finite
        coordinates, cosines or timestamps, or tags / instances that are not integers >= 0.
    """
    path = Path(path)
    v = read_ply_vertices(path)
    out = np.empty(len(v), FRAME_DTYPE)
    for key, dest in (("x", "x"), ("y", "y"), ("z", "z"), ("cos", "cos"), ("timestamp", "timestamp")):
        col = _field(v, key, path, required=key != "timestamp")
        if col is None:
            out[dest] = np.nan
        elif not np.isfinite(col).all():
            _bad(path, f"{_ALIASES.get(key, (key,))[0]}: has NaN or infinite values")
        elif key in "xyz" and col.size and np.abs(col).max() > MAX_POINT_M:
            _bad(path, f"{key}: a coordinate beyond {MAX_POINT_M:.0f} m from the sensor")
        else:
            out[dest] = col
    for key, dest in (("semantic", "tag"), ("instance", "instance")):
        col = _field(v, key, path, required=key == "semantic")
        if col is None:
            out[dest] = 0
        elif col.dtype.kind not in "iu" or (col.size and int(col.min()) < 0):
            _bad(path, f"{_ALIASES[key][0]}: must be integers >= 0")
        else:
            out[dest] = col
    return out


@functools.cache
def tag_map() -> tuple[np.ndarray, dict[int, str]]:
    """((23,) uint16 SemanticKITTI raw id per CARLA tag, tag names) from ``carla_semantic_tags.yaml``."""
    doc = load_package_yaml(TAG_FILE.read_text(encoding="utf-8"))["tags"]
    known = class_table().sk_labels
    lut = np.zeros(max(doc) + 1, np.uint16)
    for tag, row in doc.items():
        if row["semantickitti"] not in known:
            raise ValueError(f"{TAG_FILE}: tag {tag}: {row['semantickitti']} is not a SemanticKITTI raw id")
        lut[int(tag)] = row["semantickitti"]
    return lut, {int(t): str(r["name"]) for t, r in doc.items()}


def map_tags(tags: np.ndarray, source: str = "frame") -> np.ndarray:
    """(n,) uint16 SemanticKITTI raw ids of (n,) CARLA 0.9.10 tags (``UserError`` for tags above 22)."""
    lut, _ = tag_map()
    tags = np.asarray(tags)
    if tags.size and int(tags.max()) >= len(lut):
        raise UserError(f"{source}: semantic tag {int(tags.max())} is not a CARLA 0.9.10 tag (0..{len(lut) - 1})")
    return lut[tags]


def find_town(town_dir: str | Path) -> tuple[list[Path], Path | None]:
    """(frame PLY paths in frame order, pose file or None) of a KITTI-CARLA town folder."""
    town = Path(town_dir)
    if not town.is_dir():
        raise UserError(f"{town}: not a folder")
    for base in (town / "generated", town):
        frames_dir = base / "frames"
        if frames_dir.is_dir():
            frames = [p for p in frames_dir.glob("*.ply") if re.search(r"\d+", p.stem)]
            frames.sort(key=lambda p: int(re.findall(r"\d+", p.stem)[-1]))
            if not frames:
                raise UserError(f"{safeload.printable(frames_dir)}: no .ply frames")
            pose = base / "full_poses_lidar.txt"
            return frames, pose if os.path.lexists(pose) else None  # a folder or FIFO there: refused when read
    raise UserError(f"{town}: no frames/ folder (expected {town / 'generated' / 'frames'} with frame_NNNN.ply)")


def read_pose_file(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """((m, 4, 4) float64 LiDAR poses, (m,) float64 timestamps) of ``full_poses_lidar.txt``.

    Read through :mod:`generator.safeload` (a regular UTF-8 file within the table limit);
    ``#`` lines are comments. Timestamps are NaN for 12-number lines.

    Raises
    ------
    UserError
        Not 12 or 13 finite numbers on a line, a pose that is not rigid, or no poses
        (naming file and line, never quoting it).
    """
    src = str(path)
    rows = []
    for i, line in enumerate(safeload.read_text(path, source=src, max_bytes=safeload.MAX_TABLE_BYTES).splitlines(), 1):
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        try:
            vals = [float(x) for x in line.split()]
        except ValueError:
            raise SpecError(src, f"line {i}", "values must be numbers") from None
        if len(vals) not in (12, 13):
            raise SpecError(src, f"line {i}", f"expected 13 numbers (3x4 pose + timestamp), got {len(vals)}")
        if not all(math.isfinite(x) for x in vals):
            raise SpecError(src, f"line {i}", "values must be finite numbers")
        problem = rigid_problem(np.array(vals[:12]).reshape(3, 4))
        if problem:
            raise SpecError(src, f"line {i}", f"pose {problem}")
        if max(abs(vals[3]), abs(vals[7]), abs(vals[11])) > MAX_TRANSLATION_M:
            raise SpecError(src, f"line {i}", f"translation beyond {MAX_TRANSLATION_M:.0f} m from the first pose")
        rows.append(vals + [np.nan] * (13 - len(vals)))
    if not rows:
        raise SpecError(src, "", "no poses")
    a = np.array(rows)
    poses = np.repeat(np.eye(4)[None], len(a), 0)
    poses[:, :3, :4] = a[:, :12].reshape(-1, 3, 4)
    return poses, a[:, 12]


def frame_pose_index(n_lines: int, n_frames: int, frame: int, start_time: float, times: np.ndarray,
                     source: str) -> int:
    """Line of the pose file that holds the sweep-start pose of ``frame`` (see the module docstring)."""
    if np.isfinite(start_time) and np.isfinite(times).all():
        i = int(np.argmin(np.abs(times - start_time)))
        if abs(times[i] - start_time) > 1e-3:
            raise UserError(
                f"{source}: no pose at the frame's start time {start_time:.6f} s (nearest {times[i]:.6f} s)"
            )
        return i
    per = n_lines // n_frames
    if per < 1:
        raise UserError(f"{source}: {n_lines} poses for {n_frames} frames")
    return frame * per
