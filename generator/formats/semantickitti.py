"""SemanticKITTI sequences: writer and a robust reader for any dataset in that layout.

Layout (``root/sequences/NN/``)::

    velodyne/NNNNNN.bin   float32 little-endian rows (x, y, z, remission), sensor frame, metres
    labels/NNNNNN.label   uint32 little-endian per point: SemanticKITTI raw id in the low
                          16 bits, instance id in the high 16 bits
    poses.txt             cam0 pose of each scan in the first cam0 frame, 3x4 row-major
                          (see :mod:`generator.formats.kitti_calib`)
    calib.txt             P0..P3 and Tr (velodyne -> cam0)
    times.txt             seconds since the sequence start, one line per scan

Every write is atomic (:mod:`generator.atomic`). Every read problem is a
:class:`generator.errors.UserError` naming the file.
"""

from __future__ import annotations

import functools
import os
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generator import safeload
from generator.atomic import write_bytes, write_text
from generator.errors import UserError
from generator.formats.kitti_calib import lidar_poses, read_calib, rigid_problem, tr_matrix
from generator.labels import class_table

__all__ = [
    "encode_labels", "decode_labels", "write_scan", "write_labels", "write_poses", "write_times",
    "read_scan", "read_labels", "read_poses", "read_times", "read_calib", "check_raw_ids", "sequence_name",
    "sequence_dir", "list_sequences", "Sequence", "ScanRecord", "iter_sequence",
]


def encode_labels(semantic: np.ndarray, instance: np.ndarray) -> np.ndarray:
    """(n,) uint32 ``instance << 16 | semantic`` from (n,) uint16 raw ids and instance ids."""
    sem = np.asarray(semantic)
    inst = np.asarray(instance)
    if sem.max(initial=0) > 0xFFFF or inst.max(initial=0) > 0xFFFF or sem.min(initial=0) < 0 or inst.min(initial=0) < 0:
        raise ValueError("semantic and instance ids must fit in 16 bits")
    return (inst.astype(np.uint32) << np.uint32(16)) | sem.astype(np.uint32)


def decode_labels(label: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(semantic uint16, instance uint16) from (n,) uint32 labels."""
    label = np.asarray(label, np.uint32)
    return (label & np.uint32(0xFFFF)).astype(np.uint16), (label >> np.uint32(16)).astype(np.uint16)


def scan_array(xyz: np.ndarray, remission: np.ndarray) -> np.ndarray:
    """(n, 4) float32 ``.bin`` rows from (n, 3) coordinates and (n,) remission."""
    out = np.empty((len(xyz), 4), "<f4")
    out[:, :3] = xyz
    out[:, 3] = remission
    return out


def write_scan(path: str | Path, xyz: np.ndarray, remission: np.ndarray) -> None:
    """Write a ``.bin`` scan: (n, 3) float coordinates (sensor frame, metres) + (n,) remission in [0, 1]."""
    if len(xyz) != len(remission):
        raise ValueError(f"{len(xyz)} points but {len(remission)} remission values")
    write_bytes(path, scan_array(xyz, remission).tobytes())


def write_labels(path: str | Path, semantic: np.ndarray, instance: np.ndarray) -> None:
    """Write a ``.label`` file from (n,) SemanticKITTI raw ids and (n,) instance ids."""
    if len(semantic) != len(instance):
        raise ValueError(f"{len(semantic)} semantic ids but {len(instance)} instance ids")
    write_bytes(path, encode_labels(semantic, instance).astype("<u4").tobytes())


def _matrix_lines(m: np.ndarray) -> str:
    rows = np.asarray(m, np.float64)[:, :3, :4].reshape(len(m), 12)
    return "".join(" ".join(f"{v:.9e}" for v in r) + "\n" for r in rows)


def write_poses(path: str | Path, poses: np.ndarray) -> None:
    """Write ``poses.txt`` from (n, 4, 4) cam0 poses (``kitti_calib.camera_poses``)."""
    write_text(path, _matrix_lines(poses))


def write_times(path: str | Path, times: np.ndarray) -> None:
    """Write ``times.txt`` from (n,) seconds."""
    write_text(path, "".join(f"{t:e}\n" for t in np.asarray(times, np.float64)))


# -- reading ----------------------------------------------------------------------------------
# Every reader goes through :mod:`generator.safeload`: regular files only, size limits, and the
# shapes of the format checked at the border (16-byte points, 4-byte labels, 12 numbers per
# pose line, one per time line, finite numbers), one ``UserError`` line naming the file.


#: Farthest coordinate a scan point may have, metres from the sensor (LiDARs reach a few hundred).
MAX_POINT_M = 10_000.0
#: Farthest a pose in ``poses.txt`` may be from the first one, metres: with points within
#: :data:`MAX_POINT_M` the whole map stays within the reach of the semantic map's voxel keys.
MAX_TRANSLATION_M = 40_000.0


def read_scan(path: str | Path) -> np.ndarray:
    """(n, 4) float32 (x, y, z, remission) of a ``.bin`` file: every value finite, coordinates within
    :data:`MAX_POINT_M` of the sensor."""
    pts = safeload.read_array(path, "<f4", 16, finite=True).astype(np.float32, copy=False)
    if pts.size and np.abs(pts[:, :3]).max() > MAX_POINT_M:
        first = int(np.flatnonzero((np.abs(pts[:, :3]) > MAX_POINT_M).any(axis=1))[0])
        raise UserError(f"{safeload.printable(path)}: record {first}: a coordinate beyond {MAX_POINT_M:.0f} m "
                        "from the sensor")
    return pts


def read_labels(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """(semantic uint16, instance uint16) of a ``.label`` file."""
    return decode_labels(safeload.read_array(path, "<u4"))


def check_raw_ids(semantic: np.ndarray, source: str | Path) -> None:
    """Refuse SemanticKITTI raw ids that the label table does not know.

    Raises
    ------
    UserError
        ``<file>: label ids [..] are not in the SemanticKITTI label table``.
    """
    bad = np.setdiff1d(np.unique(np.asarray(semantic)), _known_raw_ids())
    if bad.size:
        shown = ", ".join(str(int(v)) for v in bad[:8]) + (", ..." if bad.size > 8 else "")
        raise UserError(f"{safeload.printable(source)}: label ids [{shown}] are not in the SemanticKITTI "
                        "label table (generator/labels/semantic-kitti.yaml)")


@functools.cache
def _known_raw_ids() -> np.ndarray:
    return np.array(sorted(class_table().sk_labels), np.int64)


def read_poses(path: str | Path) -> np.ndarray:
    """(n, 4, 4) float64 poses of a KITTI ``poses.txt`` (12 finite numbers per line, rigid, translations
    within :data:`MAX_TRANSLATION_M`)."""
    rows = safeload.read_matrix_rows(path, 12)
    far = np.flatnonzero(np.abs(rows[:, [3, 7, 11]]).max(axis=1) > MAX_TRANSLATION_M)
    if far.size:
        raise UserError(f"{safeload.printable(path)}: line {int(far[0]) + 1}: translation beyond "
                        f"{MAX_TRANSLATION_M:.0f} m from the first pose")
    for i, row in enumerate(rows):
        problem = rigid_problem(row.reshape(3, 4))
        if problem:
            raise UserError(f"{safeload.printable(path)}: line {i + 1}: pose {problem}")
    out = np.repeat(np.eye(4)[None], len(rows), 0)
    out[:, :3, :4] = rows.reshape(-1, 3, 4)
    return out


def read_times(path: str | Path) -> np.ndarray:
    """(n,) float64 seconds of a KITTI ``times.txt`` (one finite number per line)."""
    return safeload.read_matrix_rows(path, 1)[:, 0]


def _present(path: Path) -> bool:
    """Whether anything is at ``path`` (a dangling link or a FIFO too: reading it then says what is wrong)."""
    return os.path.lexists(path)


# -- sequences ---------------------------------------------------------------------------------
#: Largest sequence number urbangen writes or reads. SemanticKITTI names sequence folders by the number
#: zero-padded to two digits, and semantic-kitti-api builds every path as ``'{0:02d}'.format(int(seq))``
#: from the integers of the label config's ``split`` (``evaluate_semantics.py``, ``evaluate_panoptic.py``,
#: ``evaluate_mos.py``, ``remap_semantic_labels.py``, ``visualize.py``, ``content.py``): sequence 100 is
#: folder ``100``, read like ``00``. The format sets no upper bound; six digits (like frame numbers) are ours.
MAX_SEQUENCE = 999_999


def sequence_name(sequence: int | str) -> str:
    """Sequence folder name: the number zero-padded to two digits (``7`` -> ``07``, ``123`` -> ``123``),
    as semantic-kitti-api spells it; rejects anything but digits and numbers beyond :data:`MAX_SEQUENCE`."""
    s = str(sequence)
    if not (s.isascii() and s.isdigit()) or len(s) > 7 or int(s) > MAX_SEQUENCE:
        raise UserError(f"sequence must be a number in 00..{MAX_SEQUENCE}, got {str(sequence)[:20]!r}")
    return f"{int(s):02d}"


def sequence_dir(root: str | Path, sequence: int | str) -> Path:
    """``root/sequences/NN``."""
    return Path(root) / "sequences" / sequence_name(sequence)


#: Where a dataset folder (``urbangen generate`` / ``lidar --out D``) keeps its SemanticKITTI tree.
LIDAR_DIR = "lidar"


def semantickitti_root(folder: str | Path) -> Path:
    """The SemanticKITTI root (the folder holding ``sequences/``) a user means by ``folder``: ``folder``
    itself (KITTI's layout, semantic-kitti-api's ``--dataset``), or ``folder/lidar`` of a dataset folder
    (``folder/lidar/sequences``). A folder with neither is returned as given (its reader says what is missing)."""
    folder = Path(folder)
    if not (folder / "sequences").is_dir() and (folder / LIDAR_DIR / "sequences").is_dir():
        return folder / LIDAR_DIR
    return folder


def list_sequences(root: str | Path) -> list[str]:
    """Sequence folder names under ``root/sequences`` (digits only), in numeric order (``99`` before ``100``)."""
    base = Path(root) / "sequences"
    if not base.is_dir():
        raise UserError(f"{base}: not a SemanticKITTI dataset (no sequences/ folder, nor lidar/sequences/ of a "
                        "dataset folder)")
    return sorted((p.name for p in base.iterdir() if p.is_dir() and p.name.isascii() and p.name.isdigit()),
                  key=lambda n: (int(n), n))


@dataclass
class ScanRecord:
    """One scan of a sequence.

    Attributes
    ----------
    index : int
        Frame number (file stem).
    points : (n, 4) float32
        x, y, z, remission; sensor frame, metres.
    semantic, instance : (n,) uint16 or None
        Labels (None when the sequence has no ``labels/`` folder, e.g. a test split).
    pose : (4, 4) float64 or None
        LiDAR pose in the first LiDAR frame (``inv(Tr) @ poses[i] @ Tr``), when poses and calib exist.
    time : float or None
        Seconds from ``times.txt``.
    """

    index: int
    points: np.ndarray
    semantic: np.ndarray | None
    instance: np.ndarray | None
    pose: np.ndarray | None
    time: float | None


class Sequence:
    """Read access to ``root/sequences/NN`` of any SemanticKITTI-layout dataset."""

    def __init__(self, root: str | Path, sequence: int | str):
        self.dir = sequence_dir(root, sequence)
        self.velodyne = self.dir / "velodyne"
        self.labels_dir = self.dir / "labels"
        if not self.velodyne.is_dir():
            raise UserError(f"{self.velodyne}: missing (not a SemanticKITTI sequence)")
        stems = [p.stem for p in self.velodyne.glob("*.bin")]
        bad = [s for s in stems if not s.isdigit()]
        if bad:
            raise UserError(f"{safeload.printable(self.velodyne / (bad[0] + '.bin'))}: scan names must be frame "
                            "numbers like 000000.bin")
        self.frames: list[int] = sorted(int(s) for s in stems)
        self._stem = {int(s): s for s in stems}
        self.has_labels = self.labels_dir.is_dir()
        self.times = read_times(self.dir / "times.txt") if _present(self.dir / "times.txt") else None
        self.calib = read_calib(self.dir / "calib.txt") if _present(self.dir / "calib.txt") else None
        self.cam_poses = read_poses(self.dir / "poses.txt") if _present(self.dir / "poses.txt") else None
        for name, arr in (("times.txt", self.times), ("poses.txt", self.cam_poses)):
            if arr is not None and self.frames and len(arr) <= max(self.frames):
                raise UserError(f"{self.dir / name}: {len(arr)} lines but scans go up to frame {max(self.frames)}")

    def __len__(self) -> int:
        return len(self.frames)

    def _name(self, index: int) -> str:
        try:
            return self._stem[index]
        except KeyError:
            raise UserError(f"{self.velodyne}: no scan {index:06d}.bin") from None

    def scan_path(self, index: int) -> Path:
        return self.velodyne / f"{self._name(index)}.bin"

    def label_path(self, index: int) -> Path:
        return self.labels_dir / f"{self._name(index)}.label"

    def lidar_poses(self) -> np.ndarray | None:
        """(n, 4, 4) LiDAR poses in the first LiDAR frame, or None without poses/calib."""
        if self.cam_poses is None or self.calib is None:
            return None
        return lidar_poses(self.cam_poses, tr_matrix(self.calib, str(self.dir / "calib.txt")))

    def read_labelled(self, index: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(points (n, 4) float32, semantic (n,) uint16, instance (n,) uint16) of frame ``index``.

        Raises
        ------
        UserError
            A bad scan or label file, or a label count that differs from the point count.
        """
        pts = read_scan(self.scan_path(index))
        sem, inst = read_labels(self.label_path(index))
        if len(sem) != len(pts):
            raise UserError(
                f"{self.label_path(index)}: {len(sem)} labels but {self.scan_path(index)} has {len(pts)} points"
            )
        return pts, sem, inst

    def read(self, index: int, labels: bool = True, _poses: np.ndarray | None = None) -> ScanRecord:
        """The scan, labels (unless ``labels=False``), pose and time of frame ``index``."""
        if labels and self.has_labels:
            pts, sem, inst = self.read_labelled(index)
        else:
            pts, sem, inst = read_scan(self.scan_path(index)), None, None
        poses = self.lidar_poses() if _poses is None else _poses
        return ScanRecord(index, pts, sem, inst, None if poses is None else poses[index],
                          None if self.times is None else float(self.times[index]))

    def __iter__(self) -> Iterator[ScanRecord]:
        poses = self.lidar_poses()  # parsed once for the whole sequence
        for i in self.frames:
            yield self.read(i, True, poses)


def iter_sequence(root: str | Path, sequence: int | str) -> Iterator[ScanRecord]:
    """Iterate the scans of ``root/sequences/NN`` in frame order (see :class:`Sequence`)."""
    yield from Sequence(root, sequence)
