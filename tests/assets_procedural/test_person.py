"""People (assets_procedural/person.py): garments of their own materials, builds that vary."""

from __future__ import annotations

import numpy as np
import pytest

from assets_procedural import catalog
from generator.materials import material_table


def _of(m, name: str) -> np.ndarray:
    return m.face_material == material_table().id(name)


@pytest.mark.parametrize("pose", ["standing", "walking"])
def test_garments_have_their_own_materials_and_builds_vary(pose):
    widths = []
    for seed in range(12):
        m = catalog.build("person", np.random.default_rng(seed), height=1.75, pose=pose)
        for mat in ("clothing", "skin", "hair", "shoes"):
            assert _of(m, mat).any(), mat
        legs = m.vertices[np.unique(m.faces[_of(m, "clothing_bottom") | _of(m, "skin")])]
        assert legs[:, 2].min() < 0.3                                      # bottoms or bare legs reach the shoes
        widths.append(np.ptp(m.vertices[:, 1]))
    assert np.ptp(widths) > 0.03                                           # slim and broad builds
