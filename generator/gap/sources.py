"""Datasets ``gap`` reads: scans with remission, labels and objects, one reader per layout.

Today: any SemanticKITTI-layout folder (``sequences/NN/velodyne/*.bin`` with optional ``labels/``), ours or
KITTI's. A layout is a class with the :class:`Source` interface, chosen by :func:`open_source`; a nuScenes
reader (``samples/LIDAR_TOP/*.pcd.bin``: x, y, z, intensity 0-255, ring index) would add itself to
:data:`LAYOUTS`, hand its ring index through :attr:`ScanData.ring` (nothing to derive then) and its
intensity divided by 255.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generator.errors import UserError
from generator.formats import semantickitti as sk
from generator.gap.objects import BoxReader, box_reader
from generator.labels.sets import label_sets
from generator.safeload import printable


@dataclass
class ScanData:
    """One scan.

    Attributes
    ----------
    sequence : str
    index : int
    xyz : (n, 3) float32
        Sensor frame, metres (raw: as the sensor measured, not de-skewed).
    remission : (n,) float32
        In [0, 1].
    learning : (n,) int64 or None
        SemanticKITTI learning class (0 = unlabeled/ignored) when the dataset has labels.
    instance : (n,) int64 or None
    ring : (n,) int16 or None
        The ring when the format records it (then it is not derived).
    """

    sequence: str
    index: int
    xyz: np.ndarray
    remission: np.ndarray
    learning: np.ndarray | None
    instance: np.ndarray | None
    ring: np.ndarray | None = None


class SemanticKittiSource:
    """A SemanticKITTI-layout dataset: every sequence under ``root/sequences`` (or the ones named).

    Parameters
    ----------
    root : path-like
    role : str
        How the command line names it (``SYNTH``, ``REAL``), for messages.
    every : int
        Read every ``every``-th scan of each sequence.

    Raises
    ------
    UserError
        ``<role>: <root>: ...`` not a SemanticKITTI layout, or no scan in it.
    """

    layout = "semantickitti"

    def __init__(self, root: str | Path, role: str, every: int = 1, sequences: list[str] | None = None):
        self.root, self.role, self.every = Path(root), role, every
        try:
            names = sk.list_sequences(self.root)
        except UserError:
            raise UserError(f"{role}: {printable(self.root)}: not a SemanticKITTI-layout folder "
                            "(no sequences/ folder, nor lidar/sequences/ of a dataset folder)") from None
        self.sequences = [sk.Sequence(self.root, n) for n in (sequences or names)
                          if sequences or (self.root / "sequences" / n / "velodyne").is_dir()]
        self.frames = {s.dir.name: s.frames[::every] for s in self.sequences}
        if not sum(len(f) for f in self.frames.values()):
            raise UserError(f"{role}: {printable(self.root)}: no scans (sequences/NN/velodyne/*.bin)")
        self.has_labels = all(s.has_labels for s in self.sequences)
        self._learning = label_sets()["semantickitti"].from_raw
        self._boxes = {s.dir.name: box_reader(self.root, s.dir.name) for s in self.sequences}

    @property
    def n_scans(self) -> int:
        return sum(len(f) for f in self.frames.values())

    @property
    def has_boxes(self) -> bool:
        return all(b is not None for b in self._boxes.values())

    def boxes(self, sequence: str) -> BoxReader | None:
        return self._boxes.get(sequence)

    def sensor_name(self) -> str | None:
        """The sensor preset urbangen recorded in ``lidar_meta.json`` (None for data from elsewhere)."""
        from generator.imaging.meta_fields import load_metadata

        for s in self.sequences:
            meta = s.dir / "lidar_meta.json"
            if os.path.lexists(meta):
                sensor = load_metadata(meta).get("sensor")
                name = sensor.get("name") if isinstance(sensor, dict) else sensor
                return name if isinstance(name, str) else None
        return None

    def scans(self) -> Iterator[ScanData]:
        """Every scan read (one in ``every``), labels checked against the SemanticKITTI table."""
        for seq in self.sequences:
            for i in self.frames[seq.dir.name]:
                if self.has_labels:
                    pts, sem, inst = seq.read_labelled(i)
                    sk.check_raw_ids(sem, seq.label_path(i))
                    learning, instance = self._learning[sem], inst.astype(np.int64)
                else:
                    pts, learning, instance = sk.read_scan(seq.scan_path(i)), None, None
                yield ScanData(seq.dir.name, i, pts[:, :3], np.clip(pts[:, 3], 0.0, 1.0), learning, instance)


#: Layout name -> reader class, tried in order.
LAYOUTS = {"semantickitti": SemanticKittiSource}


def open_source(root: str | Path, role: str, every: int = 1) -> SemanticKittiSource:
    """The reader for the dataset at ``root`` (today: SemanticKITTI layout; see the module docstring)."""
    root = Path(root)
    if not root.is_dir():
        raise UserError(f"{role}: {printable(root)}: no such folder")
    if not any(root.iterdir()):
        raise UserError(f"{role}: {printable(root)}: the folder is empty")
    return LAYOUTS["semantickitti"](sk.semantickitti_root(root), role, every)
