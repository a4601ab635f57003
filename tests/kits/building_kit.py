"""Buildings of the catalog on fixed footprints, and their faces by material (asset tests)."""

from __future__ import annotations

import numpy as np

from assets_procedural import catalog
from generator.geometry import Mesh
from generator.materials import material_table

RECT = np.array([[-8.0, -5.0], [8.0, -5.0], [8.0, 5.0], [-8.0, 5.0]])
L_SHAPE = np.array([[-10.0, -8.0], [10.0, -8.0], [10.0, 0.0], [0.0, 0.0], [0.0, 8.0], [-10.0, 8.0]])
FH = 3.2


def build(seed: int, **params) -> Mesh:
    """A building of seed ``seed`` (default footprint :data:`RECT`)."""
    params.setdefault("footprint", RECT)
    return catalog.build("building", np.random.default_rng(seed), **params)


def mat(m: Mesh, *names: str) -> np.ndarray:
    """(F,) bool: the faces of ``m`` in any of the materials ``names``."""
    return np.isin(m.face_material, [material_table().id(n) for n in names])
