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


def _head_share(m) -> float:
    """Height of the head (skin and hair above the neck's top) as a share of the figure's height."""
    h = m.vertices[:, 2].max()
    hair = m.vertices[np.unique(m.faces[_of(m, "hair")])]
    return float((h - hair[:, 2].min()) / h)


def test_a_child_has_a_bigger_head_for_its_height_than_an_adult():
    g = lambda: np.random.default_rng(5)   # noqa: E731 -- the same garments and build for both
    child = catalog.build("person", g(), height=1.1, age=5.0)
    adult = catalog.build("person", g(), height=1.75, age=35.0)
    assert child.vertices[:, 2].max() == pytest.approx(1.1) and adult.vertices[:, 2].max() == pytest.approx(1.75)
    assert _head_share(child) > 1.2 * _head_share(adult)


def _bare_thighs(m) -> bool:
    """Skin on the upper thighs (between 0.4 and 0.48 of the height, above a short's hem, near the middle): a skirt."""
    c = m.vertices[m.faces].mean(1) / m.vertices[:, 2].max()
    return int((_of(m, "skin") & (c[:, 2] > 0.4) & (c[:, 2] < 0.48) & (np.abs(c[:, 1]) < 0.07)).sum()) > 10


def _shoulders(m) -> float:
    """Breadth (metres) across the shoulders and upper arms (0.72-0.8 of the height)."""
    v = m.vertices[(m.vertices[:, 2] > 0.72 * 1.75) & (m.vertices[:, 2] < 0.8 * 1.75)]
    return float(np.ptp(v[:, 1]))


def test_men_wear_no_skirt_and_have_broader_shoulders():
    skirted = [s for s in range(60) if _bare_thighs(catalog.build("person", np.random.default_rng(s), height=1.75))]
    assert skirted                                                         # the check finds skirts
    assert not any(_bare_thighs(catalog.build("person", np.random.default_rng(s), height=1.75, sex="male"))
                   for s in skirted)
    for seed in range(5):
        w = {sex: _shoulders(catalog.build("person", np.random.default_rng(seed), height=1.75, sex=sex))
             for sex in ("female", "male")}
        assert w["male"] > w["female"]
    with pytest.raises(ValueError, match="sex"):
        catalog.build("person", np.random.default_rng(0), height=1.75, sex="x")
