"""nuScenes-lidarseg's 32 classes as SemanticKITTI learning classes (``nuscenes_lidarseg.yaml``).

Checked on load: 32 classes in nuScenes' index order, each mapped to a SemanticKITTI learning class
name or to nothing (null: unlabeled).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from generator.labels.registry import _load_yaml
from generator.labels.sets import label_sets

#: Classes of nuScenes-lidarseg v1.0 (its category.json ``index`` 0 .. 31).
N_CLASSES = 32


@dataclass(frozen=True)
class LidarsegMapping:
    """Parsed ``nuscenes_lidarseg.yaml``.

    Attributes
    ----------
    names : tuple of str
        nuScenes-lidarseg class name of each index ``0 .. 31``.
    to_learning : (32,) int64
        SemanticKITTI learning class of each index (0 = unlabeled: no counterpart).
    """

    names: tuple[str, ...]
    to_learning: np.ndarray

    @property
    def dropped(self) -> tuple[str, ...]:
        """The nuScenes classes with no SemanticKITTI counterpart."""
        return tuple(n for n, c in zip(self.names, self.to_learning, strict=True) if c == 0)


@functools.cache
def lidarseg_mapping() -> LidarsegMapping:
    """The mapping (cached; see the module docstring)."""
    rows = _load_yaml("nuscenes_lidarseg.yaml")["classes"]
    learn = label_sets()["semantickitti"].names
    if len(rows) != N_CLASSES:
        raise ValueError(f"nuscenes_lidarseg.yaml: classes: {len(rows)} rows, nuScenes-lidarseg has {N_CLASSES}")
    lut = np.zeros(N_CLASSES, np.int64)
    for i, (_name, target) in enumerate(rows):
        if target is not None:
            if target not in learn[1:]:
                raise ValueError(f"nuscenes_lidarseg.yaml: classes[{i}]: {target!r} is no SemanticKITTI learning class")
            lut[i] = learn.index(target)
    lut.flags.writeable = False
    return LidarsegMapping(tuple(r[0] for r in rows), lut)
