"""Every street kind reaches Blender triangle for triangle: the town Blender evaluates has the
SceneModel's triangle count and bounds (what the LiDAR casts against is what the camera renders).

One tiny town per kind: street types (verges, medians, districts), roundabouts, pocket parks,
one-way and shared streets, all of them together, and a skewed town.
"""

from __future__ import annotations

import numpy as np
import pytest

from generator.layout import build_scene
from generator.layout.network.draw import make_grid
from generator.spec import parse_spec


def blender_matches_scene(spec, scene, tmp_path) -> None:
    """Blender's evaluated geometry of ``scene`` has its triangle count and bounds."""
    from generator.blender.renderer import Renderer
    from generator.spec.render import load_render_config

    n, bounds = Renderer(scene, spec, load_render_config("test"), tmp_path).evaluated_geometry()
    assert n == len(scene.faces)
    v = scene.vertices.astype(np.float64)
    assert np.allclose(bounds, [v.min(0), v.max(0)], atol=1e-3)


@pytest.mark.blender
def test_blender_builds_the_street_types_as_the_scene_model(tmp_path):
    """Verges, median islands, verge hedges and district lots reach Blender triangle for triangle."""
    spec = parse_spec({"name": "streets_tiny", "seed": 2,
                       "town": {"blocks_x": 1, "blocks_y": 1, "block_size_m": 40, "block_size_jitter_m": 0,
                                "margin_m": 12},
                       "streets": {"types": {"residential": 1, "boulevard": 1, "arterial": 1},
                                   "districts": {"detached": 1, "light_industry": 1}}}, "streets_tiny.json")
    scene = build_scene(spec)
    grid = make_grid(spec)
    assert {k for _, k, _ in grid.raised_rects()} == {"verge", "median"}
    blender_matches_scene(spec, scene, tmp_path)


@pytest.mark.blender
def test_blender_builds_the_roundabout_as_the_scene_model(tmp_path):
    """The island (apron, raised centre, grass), give-way lines and approach signs reach Blender
    triangle for triangle."""
    spec = parse_spec({"name": "roundabout_tiny", "seed": 2,
                       "town": {"blocks_x": 2, "blocks_y": 2, "block_size_m": 30, "block_size_jitter_m": 0,
                                "margin_m": 8},
                       "streets": {"roundabouts": 1}}, "roundabout_tiny.json")
    scene = build_scene(spec)
    assert make_grid(spec).roundabouts == {(1, 1)}
    blender_matches_scene(spec, scene, tmp_path)


@pytest.mark.blender
def test_blender_builds_the_pocket_parks_as_the_scene_model(tmp_path):
    """The parks (grass, footpath, kept sidewalks) and the T-junction caps reach Blender triangle for triangle."""
    spec = parse_spec({"name": "closed_tiny", "seed": 2,
                       "town": {"blocks_x": 2, "blocks_y": 2, "block_size_m": 30, "block_size_jitter_m": 0,
                                "margin_m": 8},
                       "streets": {"closed_streets": 1}}, "closed_tiny.json")
    scene = build_scene(spec)
    assert make_grid(spec).closed
    blender_matches_scene(spec, scene, tmp_path)


@pytest.mark.blender
def test_blender_builds_one_way_and_shared_streets_as_the_scene_model(tmp_path):
    """Paved shared carriageways, bollards, one-way arrows and dividers reach Blender triangle for triangle."""
    spec = parse_spec({"name": "oneway_shared_tiny", "seed": 5,
                       "town": {"blocks_x": 2, "blocks_y": 2, "block_size_m": 30, "block_size_jitter_m": 0,
                                "margin_m": 8},
                       "density": {"trees_per_100m": 0, "people_per_100m": 2},
                       "streets": {"types": {"one_way": 2, "shared": 1}}}, "oneway_shared_tiny.json")
    grid = make_grid(spec)
    kinds = {grid.section(s).kind for s in grid.segments}
    assert {"one_way", "shared"} <= kinds
    scene = build_scene(spec)
    assert any(o.kind == "bollard" for o in scene.objects)
    blender_matches_scene(spec, scene, tmp_path)


@pytest.mark.blender
def test_blender_builds_a_town_with_every_street_kind_as_the_scene_model(tmp_path):
    """One-way arrows, shared paving, roundabout islands and pocket parks in one town reach Blender
    triangle for triangle."""
    spec = parse_spec({"name": "full_mix_tiny", "seed": 11,
                       "town": {"blocks_x": 3, "blocks_y": 3, "block_size_m": 30, "block_size_jitter_m": 0,
                                "margin_m": 8},
                       "density": {"trees_per_100m": 0, "people_per_100m": 2},
                       "streets": {"types": {"one_way": 3, "shared": 1}, "roundabouts": 0.5,
                                   "closed_streets": 0.4}}, "full_mix_tiny.json")
    grid = make_grid(spec)
    assert any(grid.section(s).one_way for s in grid.segments) and grid.roundabouts and grid.closed
    scene = build_scene(spec)
    blender_matches_scene(spec, scene, tmp_path)


@pytest.mark.blender
def test_blender_builds_the_skewed_town_triangle_for_triangle(tmp_path):
    """Baked shaped objects and turned rigid ones reach Blender as the LiDAR sees them."""
    doc = {"name": "skewed_small", "seed": 5, "town": {"blocks_x": 1, "blocks_y": 1, "block_size_m": 40, "margin_m": 5},
           "streets": {"intersection_angle_deg": [62, 62]}}
    spec = parse_spec(doc, "skewed_small.json")
    scene = build_scene(spec)
    assert scene.town_map is not None
    blender_matches_scene(spec, scene, tmp_path)
