"""Street variety combined: shared streets, roundabouts and closed streets in one town.

Each kind has its own test module; this one checks that they live together (the layout
invariants, a stretch of traffic without contact) and that the one combination the lane graph
cannot build yet -- one-way streets with roundabouts or closed streets -- is refused as a spec
error naming the field, before anything is built.
"""

from __future__ import annotations

import numpy as np
import pytest

from generator.errors import SpecError
from generator.layout.assemble import build_scene
from generator.layout.streets import make_grid
from generator.spec.load import parse_spec
from generator.traffic.build import build_world
from generator.traffic.lanes import boxes_overlap
from test_streets import _no_collisions, _rests_on_ground

SECONDS = 20.0


def mixed_spec(seed: int, traffic: bool = False):
    doc = {"name": "mixed_town", "seed": seed,
           "town": {"blocks_x": 3, "blocks_y": 3, "block_size_m": 45, "block_size_jitter_m": 6, "margin_m": 10},
           "density": {"moving_cars_per_100m": 0, "people_per_100m": 3},
           "streets": {"types": {"plain": 1, "residential": 1, "shared": 2}, "roundabouts": 0.5,
                       "closed_streets": 0.3}}
    if traffic:
        doc["traffic"] = {"cars_per_km": 25, "trucks_per_km": 2, "buses_per_km": 1, "cyclists_per_km": 3,
                          "pedestrians_per_100m": 1.0}
    return parse_spec(doc, "mixed_town.json")


@pytest.mark.parametrize("seed", [3, 8])
def test_shared_streets_roundabouts_and_closures_together_keep_the_layout_invariants(seed):
    spec = mixed_spec(seed)
    grid = make_grid(spec)
    kinds = {grid.section(s).kind for s in grid.segments}
    assert "shared" in kinds and grid.roundabouts and grid.closed, (kinds, grid.roundabouts, grid.closed)
    scene = build_scene(spec)
    _no_collisions(scene)
    _rests_on_ground(spec, grid, scene)


def test_traffic_in_a_mixed_town_never_touches():
    spec = mixed_spec(3, traffic=True)
    scene = build_scene(spec)
    world = build_world(spec, scene, SECONDS)
    assert len(world.actors) > 5
    for t in np.arange(0.0, SECONDS, 0.2):
        q = np.stack([b.corners_xy() for b in world.boxes(t)])
        ov = boxes_overlap(q, q)
        np.fill_diagonal(ov, False)
        assert not ov.any(), f"actors {np.argwhere(ov)[0]} overlap at t={t:.1f}"


@pytest.mark.parametrize("field", ["roundabouts", "closed_streets"])
def test_one_way_with_roundabouts_or_closures_is_one_line_spec_error(field):
    doc = {"name": "x", "seed": 1, "streets": {"types": {"plain": 1, "one_way": 1}, field: 0.5}}
    with pytest.raises(SpecError) as e:
        parse_spec(doc, "scenes/x.json")
    msg = str(e.value)
    assert msg.startswith(f"scenes/x.json: streets.{field}: cannot be combined with one-way streets") and "\n" not in msg
    doc["streets"]["types"]["one_way"] = 0            # either at 0 is fine
    parse_spec(doc, "scenes/x.json")
