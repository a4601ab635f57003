"""build_scene returns the town with what it was built from (the grid and the asset library)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from generator.layout import Town, build_scene
from generator.layout.network import make_grid
from generator.spec.towns import library_seed
from generator.traffic import build_world
from generator.world.scene import SceneModel


def test_the_town_keeps_its_grid_and_library(test_spec, test_scene):
    assert isinstance(test_scene, Town) and isinstance(test_scene, SceneModel)
    grid = make_grid(test_spec)
    assert np.array_equal(test_scene.grid.xs, grid.xs) and np.array_equal(test_scene.grid.ys, grid.ys)
    assert test_scene.grid.segments == grid.segments
    assert test_scene.library.seed == test_spec.seed
    used = {o.prototype for o in test_scene.objects}
    assert any(k in used for k in test_scene.library.protos)        # the library the objects came from
    assert test_scene.town_map is None and test_scene.layout is None


def test_a_redrawn_town_builds_from_its_library_seed(test_spec):
    town = dataclasses.replace(test_spec, seed=99, asset_seed=test_spec.seed, town_index=1)
    lib = build_scene(town).library
    assert lib.seed == library_seed(town) != test_spec.seed               # a fresh library (assets.redraw_every_towns)
    assert lib.count("car", 0) == test_spec.assets.variants.car
    shared = dataclasses.replace(town, assets=dataclasses.replace(town.assets, redraw_every_towns=None))
    assert build_scene(shared).library.seed == test_spec.seed              # null: the spec seed's library


def test_traffic_needs_the_town_not_a_bare_scene(default_spec, test_scene):
    bare = SceneModel(**{f.name: getattr(test_scene, f.name) for f in dataclasses.fields(SceneModel)})
    with pytest.raises(TypeError, match="Town"):
        build_world(default_spec, bare, 1.0)
