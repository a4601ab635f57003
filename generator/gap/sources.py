"""Datasets ``gap`` reads: scans with remission, labels and objects, one reader per layout.

Two layouts (:data:`LAYOUTS`, chosen by :func:`open_source`): any SemanticKITTI-layout folder
(``sequences/NN/velodyne/*.bin`` with optional ``labels/``), ours or KITTI's; and a nuScenes root
(:mod:`generator.gap.nuscenes`: ``v1.0-*/`` tables, ``samples/LIDAR_TOP/*.pcd.bin``, optional lidarseg),
real or ``urbangen export nuscenes``. Every reader has the same interface: ``layout``, ``root``, ``role``,
``n_scans``, ``has_labels``, ``has_instances``, ``has_boxes``, ``boxes(sequence)``, ``sensor_name()``,
``default_sensor()``
(the preset the ring fit uses unless ``--sensor`` says otherwise) and ``scans()`` yielding
:class:`~generator.gap.scan.ScanData` (a format that records rings hands them through ``ScanData.ring``).
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from generator.errors import UserError
from generator.formats import semantickitti as sk
from generator.gap.nuscenes import NuScenesSource, is_nuscenes_root
from generator.gap.objects import BoxReader, box_reader
from generator.gap.scan import ScanData
from generator.labels.sets import label_sets
from generator.safeload import printable


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
    def has_instances(self) -> bool:
        """SemanticKITTI labels carry instance ids."""
        return self.has_labels

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

    def default_sensor(self) -> str:
        """The sensor table for the ring fit when ``--sensor`` names none: the HDL-64E S3 (KITTI's and ours)."""
        return "hdl64e"

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
LAYOUTS = {"nuscenes": NuScenesSource, "semantickitti": SemanticKittiSource}


def open_source(root: str | Path, role: str, every: int = 1, nuscenes_version: str | None = None):
    """The reader for the dataset at ``root``: a nuScenes root (a ``v1.0-*`` folder or ``samples/LIDAR_TOP``)
    or else a SemanticKITTI layout (see the module docstring)."""
    root = Path(root)
    if not root.is_dir():
        raise UserError(f"{role}: {printable(root)}: no such folder")
    if not any(root.iterdir()):
        raise UserError(f"{role}: {printable(root)}: the folder is empty")
    if is_nuscenes_root(root):
        return LAYOUTS["nuscenes"](root, role, every, nuscenes_version)
    return LAYOUTS["semantickitti"](sk.semantickitti_root(root), role, every)
