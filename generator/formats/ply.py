"""PLY export of one labelled scan (binary little-endian; opens in CloudCompare, MeshLab, Open3D).

Vertex properties: ``float x, y, z`` (sensor frame, metres), ``float intensity``,
``ushort semantic`` (SemanticKITTI raw id), ``ushort instance``, ``uchar red, green, blue``
(class colour).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from generator import safeload
from generator.atomic import write_bytes
from generator.errors import UserError

PLY_DTYPE = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("intensity", "<f4"), ("semantic", "<u2"),
                      ("instance", "<u2"), ("red", "u1"), ("green", "u1"), ("blue", "u1")])
_PLY_TYPES = {"<f4": "float", "<u2": "ushort", "|u1": "uchar"}


def ply_bytes(xyz: np.ndarray, intensity: np.ndarray, semantic: np.ndarray, instance: np.ndarray,
              rgb: np.ndarray, comment: str = "urbangen LiDAR scan") -> bytes:
    """The file content; arrays (n, 3) float, (n,) float, (n,) uint16, (n,) uint16, (n, 3) uint8."""
    n = len(xyz)
    v = np.empty(n, PLY_DTYPE)
    v["x"], v["y"], v["z"] = xyz[:, 0], xyz[:, 1], xyz[:, 2]
    v["intensity"], v["semantic"], v["instance"] = intensity, semantic, instance
    v["red"], v["green"], v["blue"] = rgb[:, 0], rgb[:, 1], rgb[:, 2]
    header = ["ply", "format binary_little_endian 1.0", f"comment {comment}", f"element vertex {n}"]
    header += [f"property {_PLY_TYPES[PLY_DTYPE[name].str]} {name}" for name in PLY_DTYPE.names]
    header.append("end_header")
    return ("\n".join(header) + "\n").encode("ascii") + v.tobytes()


def write_ply(path: str | Path, xyz, intensity, semantic, instance, rgb, comment: str = "urbangen LiDAR scan") -> None:
    """Write :func:`ply_bytes` atomically."""
    write_bytes(path, ply_bytes(np.asarray(xyz), np.asarray(intensity), np.asarray(semantic),
                                np.asarray(instance), np.asarray(rgb), comment))


def read_ply(path: str | Path) -> np.ndarray:
    """Read a file written by :func:`write_ply` back as a (n,) :data:`PLY_DTYPE` array.

    Read through :mod:`generator.safeload` (a regular file within the array size limit).

    Raises
    ------
    UserError
        Not a PLY of this layout, or a vertex count that disagrees with the data (one line,
        never quoting the file).
    """
    data = safeload.read_bytes(path, max_bytes=safeload.MAX_ARRAY_BYTES)
    end = data.find(b"end_header\n", 0, 64 * 1024)
    where = safeload.printable(path)
    if not data.startswith(b"ply\n") or end < 0:
        raise UserError(f"{where}: not a PLY file")
    counts = [
        h.split()[2:] for h in data[:end].decode("ascii", "replace").splitlines() if h.startswith("element vertex")
    ]
    if len(counts) != 1 or len(counts[0]) != 1 or not re.fullmatch(r"[0-9]{1,12}", counts[0][0]):
        raise UserError(f"{where}: PLY header needs one 'element vertex <count>' line with a count >= 0")
    n = int(counts[0][0])
    body = data[end + len(b"end_header\n"):]
    if len(body) != n * PLY_DTYPE.itemsize:
        raise UserError(f"{where}: {len(body)} bytes of vertex data for {n} vertices of {PLY_DTYPE.itemsize} bytes")
    return np.frombuffer(body, PLY_DTYPE)
