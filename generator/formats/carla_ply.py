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
import re
from pathlib import Path

import numpy as np
import yaml

from generator.errors import UserError
from generator.labels import class_table

TAG_FILE = Path(__file__).resolve().with_name("carla_semantic_tags.yaml")
_PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2",
    "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}
_ALIASES = {"cos": ("cos_angle_lidar_surface", "cos", "CosAngle"), "semantic": ("semantic", "ObjTag", "tag"),
            "instance": ("instance", "ObjIdx"), "timestamp": ("timestamp",)}
#: What :func:`read_frame` returns per point.
FRAME_DTYPE = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("cos", "<f4"), ("timestamp", "<f8"),
                        ("instance", "<u4"), ("tag", "<u4")])


def read_ply_vertices(path: str | Path) -> np.ndarray:
    """The ``vertex`` element of a binary PLY as a structured array (fields named as in the header).

    Raises
    ------
    UserError
        Not a PLY, ASCII format, list properties, unknown types or a size mismatch (naming the file).
    """
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as e:
        raise UserError(f"{path}: cannot read: {e.strerror or e}") from None
    end = data.find(b"end_header")
    if not data.startswith(b"ply") or end < 0:
        raise UserError(f"{path}: not a PLY file")
    body_at = data.index(b"\n", end) + 1
    header = data[:end].decode("ascii", "replace").splitlines()
    fmt, fields, n, current, elements = None, [], None, None, []
    for line in header[1:]:
        words = line.split()
        if not words or words[0] in ("comment", "obj_info"):
            continue
        if words[0] == "format":
            fmt = words[1] if len(words) > 1 else None
        elif words[0] == "element":
            current = words[1]
            elements.append(current)
            if current == "vertex":
                n = int(words[2])
        elif words[0] == "property" and current == "vertex":
            if words[1] == "list" or words[1] not in _PLY_TYPES or len(words) != 3:
                raise UserError(f"{path}: unsupported vertex property {' '.join(words[1:])!r}")
            fields.append((words[2], _PLY_TYPES[words[1]]))
    if fmt not in ("binary_little_endian", "binary_big_endian"):
        raise UserError(f"{path}: PLY format {fmt!r} not supported (binary_little_endian or binary_big_endian)")
    if n is None or not elements or elements[0] != "vertex":
        raise UserError(f"{path}: the first PLY element must be 'vertex'")
    order = "<" if fmt == "binary_little_endian" else ">"
    dtype = np.dtype([(name, order + t) for name, t in fields])
    if len(data) - body_at < n * dtype.itemsize:
        raise UserError(f"{path}: {len(data) - body_at} bytes of vertex data for {n} vertices of {dtype.itemsize} bytes (truncated)")
    return np.frombuffer(data, dtype, count=n, offset=body_at)


def _field(v: np.ndarray, key: str, path: Path, required: bool = True):
    for name in _ALIASES.get(key, (key,)):
        if name in v.dtype.names:
            return v[name]
    if required:
        raise UserError(f"{path}: PLY has no '{_ALIASES.get(key, (key,))[0]}' property (has: {', '.join(v.dtype.names)})")
    return None


def read_frame(path: str | Path) -> np.ndarray:
    """One KITTI-CARLA frame as (n,) :data:`FRAME_DTYPE` (timestamp NaN when the PLY has none)."""
    path = Path(path)
    v = read_ply_vertices(path)
    out = np.empty(len(v), FRAME_DTYPE)
    for k in ("x", "y", "z"):
        out[k] = _field(v, k, path)
    out["cos"] = _field(v, "cos", path)
    out["tag"] = _field(v, "semantic", path)
    inst = _field(v, "instance", path, required=False)
    out["instance"] = 0 if inst is None else inst
    ts = _field(v, "timestamp", path, required=False)
    out["timestamp"] = np.nan if ts is None else ts
    xyz = np.stack([out["x"], out["y"], out["z"]], -1)
    if not np.isfinite(xyz).all():
        raise UserError(f"{path}: x, y, z have NaN or infinite values")
    return out


@functools.cache
def tag_map() -> tuple[np.ndarray, dict[int, str]]:
    """((23,) uint16 SemanticKITTI raw id per CARLA tag, tag names) from ``carla_semantic_tags.yaml``."""
    doc = yaml.safe_load(TAG_FILE.read_text(encoding="utf-8"))["tags"]
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
                raise UserError(f"{frames_dir}: no .ply frames")
            pose = base / "full_poses_lidar.txt"
            return frames, pose if pose.is_file() else None
    raise UserError(f"{town}: no frames/ folder (expected {town / 'generated' / 'frames'} with frame_NNNN.ply)")


def read_pose_file(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """((m, 4, 4) float64 LiDAR poses, (m,) float64 timestamps) of ``full_poses_lidar.txt``."""
    path = Path(path)
    rows = []
    for i, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        try:
            vals = [float(x) for x in line.split()]
        except ValueError:
            raise UserError(f"{path}: line {i}: values must be numbers") from None
        if len(vals) not in (12, 13):
            raise UserError(f"{path}: line {i}: expected 13 numbers (3x4 pose + timestamp), got {len(vals)}")
        rows.append(vals + [np.nan] * (13 - len(vals)))
    if not rows:
        raise UserError(f"{path}: no poses")
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
            raise UserError(f"{source}: no pose at the frame's start time {start_time:.6f} s (nearest {times[i]:.6f} s)")
        return i
    per = n_lines // n_frames
    if per < 1:
        raise UserError(f"{source}: {n_lines} poses for {n_frames} frames")
    return frame * per
