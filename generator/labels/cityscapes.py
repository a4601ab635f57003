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
    table : dict of int to (str, int, bool, (int, int, int), int)
        Label id -> (name, train id (255: ignored), has instances, RGB colour, the SemanticKITTI raw id
        a point takes when a model predicts the label for its pixel).
    """

    table: dict[int, tuple[str, int, bool, tuple[int, int, int], int]]

    @property
    def names(self) -> list[str]:
        """Name of every label id."""
        return [self.table[i][0] for i in range(len(self.table))]

    @property
    def train_ids(self) -> np.ndarray:
        """(n,) uint8 train id of every label id (255 = ignored)."""
        return np.array([self.table[i][1] for i in range(len(self.table))], np.uint8)

    @property
    def colors(self) -> np.ndarray:
        """(n, 3) uint8 RGB colour of every label id."""
        return np.array([self.table[i][3] for i in range(len(self.table))], np.uint8)

    @property
    def semantickitti(self) -> np.ndarray:
        """(n,) uint16 SemanticKITTI raw id of every label id (for predicted labels projected onto points)."""
        return np.array([self.table[i][4] for i in range(len(self.table))], np.uint16)

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
        If the ids are not ``0 .. n - 1`` or a row lacks a field (see the file's header).
    """
    raw = _load_yaml("cityscapes.yaml")["ids"]
    if sorted(raw) != list(range(len(raw))):
        raise ValueError(f"cityscapes.yaml: label ids must be 0..{len(raw) - 1}")
    table = {}
    for i in range(len(raw)):
        row = raw[i]
        if not (isinstance(row, dict) and {"name", "train", "instances", "color", "semantickitti"} <= set(row)
                and len(row["color"]) == 3):
            raise ValueError(f"cityscapes.yaml: label {i}: expected name, train, instances, color [r, g, b], "
                             "semantickitti")
        table[i] = (str(row["name"]), int(row["train"]), bool(row["instances"]), tuple(int(c) for c in row["color"]),
                    int(row["semantickitti"]))
    return CityscapesLabels(table)
