"""Cityscapes' label table, as data (``cityscapes.yaml``): names, train ids, instance classes, colours.

The native classes map to Cityscapes label ids through ``classes.yaml``'s ``cityscapes`` column
(:attr:`generator.labels.ClassTable.to_cityscapes`); this is the table of those ids themselves, as
cityscapesScripts' ``helpers/labels.py`` defines it, for the export (:mod:`generator.formats.cityscapes`)
and the statistics (:mod:`generator.stats.class_mix`).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from generator.labels.registry import _load_yaml


@dataclass(frozen=True)
class CityscapesLabels:
    """Cityscapes' labels, ids ``0 .. n - 1``.

    Attributes
    ----------
    table : dict of int to (str, int, bool, (int, int, int))
        Label id -> (name, train id (255: ignored), has instances, RGB colour).
    """

    table: dict[int, tuple[str, int, bool, tuple[int, int, int]]]

    @property
    def train_ids(self) -> np.ndarray:
        """(n,) uint8 train id of every label id (255 = ignored)."""
        return np.array([self.table[i][1] for i in range(len(self.table))], np.uint8)

    @property
    def colors(self) -> np.ndarray:
        """(n, 3) uint8 RGB colour of every label id."""
        return np.array([self.table[i][3] for i in range(len(self.table))], np.uint8)

    @property
    def instance_ids(self) -> tuple[int, ...]:
        """Label ids of the classes with instances (person, rider, vehicles)."""
        return tuple(i for i, row in self.table.items() if row[2])

    @property
    def train_classes(self) -> tuple[tuple[int, str], ...]:
        """``(label id, name)`` of the 19 evaluated classes, in train-id order."""
        rows = sorted((row[1], i, row[0]) for i, row in self.table.items() if row[1] != 255)
        return tuple((i, name) for _, i, name in rows)


@functools.lru_cache(maxsize=1)
def cityscapes_labels() -> CityscapesLabels:
    """The table of ``cityscapes.yaml`` (read once).

    Raises
    ------
    ValueError
        If the ids are not ``0 .. n - 1`` or a row is not ``[name, train id, has instances, [r, g, b]]``.
    """
    raw = _load_yaml("cityscapes.yaml")["labels"]
    if sorted(raw) != list(range(len(raw))):
        raise ValueError(f"cityscapes.yaml: label ids must be 0..{len(raw) - 1}")
    table = {}
    for i in range(len(raw)):
        row = raw[i]
        if not (isinstance(row, list) and len(row) == 4 and len(row[3]) == 3):
            raise ValueError(f"cityscapes.yaml: label {i}: expected [name, train id, has instances, [r, g, b]]")
        table[i] = (str(row[0]), int(row[1]), bool(row[2]), tuple(int(c) for c in row[3]))
    return CityscapesLabels(table)
