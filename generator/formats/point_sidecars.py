"""Per-point side files of an urbangen SemanticKITTI sequence, aligned row by row with the ``.bin``.

KITTI's ``.bin`` keeps only x, y, z, remission and the ``.label`` file only the SemanticKITTI
raw id, which merges native classes (road_marking and crosswalk -> 60 lane-marking, curb and
sidewalk -> 48, vegetation and tree_crown -> 70, traffic_light and traffic_sign -> 81). Fusion
needs two more facts per point, written beside the scans:

=================================  =======  ==================================================
file                               dtype    content
=================================  =======  ==================================================
``point_times/NNNNNN.bin``         float32  firing offset after the sweep start, seconds (0 with
                                            motion skew off): what de-skewing needs
``native_labels/NNNNNN.bin``       uint8    native class id (``generator/labels/classes.yaml``)
``point_rings/NNNNNN.bin``         uint8    beam row by elevation, 0 = highest (the scanner's
                                            ``ring``): what the nuScenes export's ring column needs
=================================  =======  ==================================================

All little-endian, one value per point in the order of the ``.bin`` rows. Datasets from
elsewhere lack them (and datasets made before ``point_rings`` existed lack that one); readers
return None then.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from generator import safeload
from generator.atomic import write_bytes
from generator.errors import UserError
from generator.labels import class_table

TIMES_DIR = "point_times"
NATIVE_DIR = "native_labels"
RINGS_DIR = "point_rings"
#: (folder, dtype) of each side file.
SIDECARS = {TIMES_DIR: "<f4", NATIVE_DIR: "u1", RINGS_DIR: "u1"}


def write_point_sidecars(seq_dir: str | Path, stem: str, times: np.ndarray, native: np.ndarray,
                         rings: np.ndarray | None = None) -> None:
    """Write the side files of scan ``stem`` (atomically; ``point_rings`` only when ``rings`` is given).

    Parameters
    ----------
    seq_dir : path-like
        ``root/sequences/NN``.
    stem : str
        ``NNNNNN``.
    times : (n,) float
        Firing offsets, seconds.
    native : (n,) uint8
        Native class ids.
    rings : (n,) uint8, optional
        Beam rows (0 = highest beam).
    """
    if len(times) != len(native) or (rings is not None and len(rings) != len(times)):
        raise ValueError(f"{len(times)} times but {len(native)} native labels"
                         + ("" if rings is None else f" and {len(rings)} rings"))
    write_bytes(Path(seq_dir) / TIMES_DIR / f"{stem}.bin", np.asarray(times, "<f4").tobytes())
    write_bytes(Path(seq_dir) / NATIVE_DIR / f"{stem}.bin", np.asarray(native, "u1").tobytes())
    if rings is not None:
        write_bytes(Path(seq_dir) / RINGS_DIR / f"{stem}.bin", np.asarray(rings, "u1").tobytes())


def read_sidecar(seq_dir: str | Path, folder: str, index: int, n_points: int) -> np.ndarray | None:
    """(n,) array of side file ``folder`` for scan ``index``, or None when the file does not exist.

    Read through :mod:`generator.safeload` (a regular file, whole records); firing times must
    be finite, native ids within the class table.

    Raises
    ------
    UserError
        When it cannot be read (a folder, a FIFO, a symlink loop...), its length disagrees
        with the scan's ``n_points``, or its values are out of range.
    """
    path = Path(seq_dir) / folder / f"{index:06d}.bin"
    if not os.path.lexists(path):
        return None
    values = safeload.read_array(path, SIDECARS[folder], finite=True)
    if len(values) != n_points:
        raise UserError(f"{path}: {len(values)} values but the scan has {n_points} points")
    if folder == NATIVE_DIR:
        n_classes = len(class_table())
        if values.size and int(values.max()) >= n_classes:
            raise UserError(f"{path}: native class id {int(values.max())} is not in the class table "
                            f"(0..{n_classes - 1}, generator/labels/classes.yaml)")
    return values
