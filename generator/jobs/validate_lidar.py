"""``urbangen validate``, LiDAR part: every sequence under ``DIR/lidar`` checked for what the readers assume.

Per scan: the ``.bin`` is whole 16-byte points with finite values, its ``.label`` holds one
label per point and only ids of the SemanticKITTI label table, the side files
(``point_times/``, ``native_labels/``) match the point count with finite times and native
ids of the class table. Per sequence: ``poses.txt`` has 12 finite numbers per line, one line
per scan, rigid poses; ``times.txt`` one finite number per line, one per scan, strictly
increasing; ``calib.txt`` has ``P0``..``P3`` and a rigid ``Tr``; ``lidar_meta.json`` is
readable and its sweep poses well formed. Every problem is one line; nothing raises.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from generator import safeload
from generator.errors import SpecError, UserError
from generator.formats import kitti_calib
from generator.formats import semantickitti as sk
from generator.formats.point_sidecars import SIDECARS, read_sidecar
from generator.labels import class_table

META_NAME = "lidar_meta.json"


def rel(path: Path, root: Path) -> str:
    """``path`` relative to ``root`` when inside it, printable (one line whatever the file names)."""
    try:
        return safeload.printable(path.relative_to(root))
    except ValueError:
        return safeload.printable(path)


def reason(e: UserError, path: Path | str) -> str:
    """The reason of a reader's one-line error about ``path``, without the file name it starts with."""
    if isinstance(e, SpecError):
        return f"{e.field}: {e.reason}" if e.field else e.reason
    return str(e).removeprefix(f"{safeload.printable(path)}: ")


def check_scan(seq: Path, b: Path, root: Path, known: np.ndarray) -> list[str]:
    """Problems of one scan ``b`` of sequence folder ``seq``: its points, labels and side files."""
    try:
        pts = sk.read_scan(b)
    except UserError as e:
        return [f"{rel(b, root)}: {reason(e, b)}"]
    lab = seq / "labels" / (b.stem + ".label")
    if not os.path.lexists(lab):
        return [f"{rel(b, root)}: no labels/{safeload.printable(b.stem)}.label"]
    try:
        sem, _ = sk.read_labels(lab)
    except UserError as e:
        return [f"{rel(lab, root)}: {reason(e, lab)}"]
    if len(sem) != len(pts):
        return [f"{rel(lab, root)}: {len(sem)} labels for {len(pts)} points"]
    problems = []
    bad = np.setdiff1d(np.unique(sem), known)
    if bad.size:
        problems.append(f"{rel(lab, root)}: label ids {bad[:8].tolist()} are not in the label table")
    if b.stem.isdigit():
        for folder in SIDECARS:
            try:
                read_sidecar(seq, folder, int(b.stem), len(pts))
            except UserError as e:
                problems.append(f"{rel(seq / folder / b.name, root)}: {reason(e, seq / folder / b.name)}")
    return problems


def _table(path: Path, root: Path, reader, n_scans: int, what: str) -> tuple[list[str], np.ndarray | None]:
    if not os.path.lexists(path):
        return [f"{rel(path, root)}: missing"], None
    try:
        rows = reader(path)
    except UserError as e:
        return [f"{rel(path, root)}: {reason(e, path)}"], None
    if len(rows) != n_scans:
        return [f"{rel(path, root)}: {len(rows)} {what} for {n_scans} scans"], rows
    return [], rows


def check_tables(seq: Path, root: Path, n_scans: int) -> list[str]:
    """Problems of ``poses.txt``, ``times.txt`` and ``calib.txt`` of one sequence."""
    problems, _ = _table(seq / "poses.txt", root, sk.read_poses, n_scans, "rows")  # finite, rigid, near
    more, times = _table(seq / "times.txt", root, sk.read_times, n_scans, "rows")
    problems += more
    if times is not None and len(times) > 1 and (np.diff(times) <= 0).any():
        line = int(np.flatnonzero(np.diff(times) <= 0)[0]) + 2
        problems.append(f"{rel(seq / 'times.txt', root)}: line {line}: times must increase strictly")
    calib = seq / "calib.txt"
    try:
        parsed = kitti_calib.read_calib(calib)
        missing = [k for k in kitti_calib.CALIB_KEYS if k not in parsed]
        if missing:
            problems.append(f"{rel(calib, root)}: missing {', '.join(missing)}")
        else:
            kitti_calib.tr_matrix(parsed, str(calib))
    except UserError as e:
        problems.append(f"{rel(calib, root)}: {reason(e, calib)}")
    return problems


def check_meta(seq: Path, root: Path, n_scans: int) -> list[str]:
    """Problems of the sequence's ``lidar_meta.json`` (when it has one): sweep poses, and
    ``image_frames`` naming sweeps the sequence has."""
    from generator.imaging.meta_fields import image_sweeps, load_metadata, sweep_poses

    path = seq / META_NAME
    if not os.path.lexists(path):
        return []
    try:
        meta = load_metadata(path, rel(path, root))
        sweep_poses(meta, rel(path, root))
        beyond = sorted(k for k, j in image_sweeps(meta, rel(path, root)).items() if j >= n_scans)
    except UserError as e:
        return [str(e)]
    if beyond:
        return [f"{rel(path, root)}: image_frames: image {beyond[0]} is paired with a sweep beyond the "
                f"sequence's {n_scans} scans"]
    return []


def check_lidar(root: Path) -> tuple[list[str], int]:
    """Problems of every sequence under ``root/lidar`` and the number of scans checked."""
    lidar = root / "lidar"
    if not (lidar / "sequences").is_dir():
        return [], 0
    known = np.array(sorted(class_table().sk_labels), np.int64)
    problems, n = [], 0
    for name in sk.list_sequences(lidar):
        seq = lidar / "sequences" / name
        bins = sorted((seq / "velodyne").glob("*.bin"))
        n += len(bins)
        for b in bins:
            problems += check_scan(seq, b, root, known)
        problems += check_tables(seq, root, len(bins))
        problems += check_meta(seq, root, len(bins))
    return problems, n
