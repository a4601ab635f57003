"""One scan as ``gap`` measures it, whatever layout it was read from."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


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
