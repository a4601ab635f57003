"""Leaves as geometry: sprays of leaf triangles, crowns of leaf clusters, species that differ."""

from __future__ import annotations

import numpy as np
import pytest

from assets_procedural import foliage
from assets_procedural.vegetation import TRI_BUDGET, tree
from generator.materials import material_table

SPECIES = ("plane", "linden", "birch", "young", "conifer")


def _leaves(m, material: str):
    """(n, 3, 3) the triangles of ``material`` in ``m``."""
    return m.vertices[m.faces[m.face_material == material_table().id(material)]]


def _area(t: np.ndarray) -> np.ndarray:
    return 0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1)


def test_a_spray_is_a_fan_of_separate_leaf_triangles():
    rng = np.random.default_rng(0)
    leaf = foliage.LEAVES["heart"]
    centre = rng.normal(size=(50, 3))
    m = foliage.sprays(rng, centre, rng.normal(size=(50, 3)), leaf, "tree_crown", "leaves")
    assert m.n_faces == 50 * leaf.per_spray
    assert len(np.unique(m.faces)) == 3 * m.n_faces, "every leaf is its own island (per-leaf shading)"
    t = m.vertices[m.faces]
    reach = np.linalg.norm(t - np.repeat(centre, leaf.per_spray, 0)[:, None], axis=2).max(1)
    assert (reach <= 1.2 * leaf.length[1] * 1.2).all() and (reach >= 0.9 * leaf.length[0]).all()
    assert (_area(t) > 0.3 * leaf.width * leaf.length[0] ** 2).all(), "no sliver leaves"


@pytest.mark.parametrize("species", SPECIES)
def test_a_crown_is_hundreds_of_leaf_sprays_round_dark_cores_within_the_budget(species):
    for seed, height in ((0, 5.0), (1, 10.0), (2, 16.0)):
        m = tree(np.random.default_rng(seed), height, species)
        assert m.n_faces <= TRI_BUDGET
        leaf = foliage.LEAVES[{"plane": "broad", "linden": "heart", "birch": "narrow", "young": "ovate",
                               "conifer": "needle"}[species]]
        core = "needles" if species == "conifer" else "leaf_shade"
        n_leaf = len(_leaves(m, "leaves_birch" if species == "birch" else ("needles" if species == "conifer"
                                                                            else "leaves")))
        n_core = len(_leaves(m, core)) if species != "conifer" else 0
        assert n_leaf >= 250 * leaf.per_spray // 2, f"{species}: only {n_leaf} leaf triangles"
        assert species == "conifer" or 0 < n_core < n_leaf / 2, "a dark core under many more leaves"


def test_species_differ_in_leaf_size_and_shape():
    size = {}
    for sp, mat in (("plane", "leaves"), ("linden", "leaves"), ("birch", "leaves_birch")):
        t = _leaves(tree(np.random.default_rng(4), 10.0, sp), mat)
        edges = np.linalg.norm(t - np.roll(t, 1, axis=1), axis=2)
        size[sp] = (np.median(_area(t)), np.median(edges.max(1) / edges.min(1)))
    assert size["plane"][0] > 1.3 * size["linden"][0] > 1.3 * size["birch"][0], size
    assert size["birch"][1] > size["linden"][1] + 0.5, "birch leaves are narrow, linden leaves broad"


def test_same_seed_same_tree_bytes():
    a, b = tree(np.random.default_rng(7), 9.0, "linden"), tree(np.random.default_rng(7), 9.0, "linden")
    assert a.vertices.tobytes() == b.vertices.tobytes() and a.faces.tobytes() == b.faces.tobytes()
    assert tree(np.random.default_rng(8), 9.0, "linden").vertices.tobytes() != a.vertices.tobytes()
