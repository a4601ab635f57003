"""The traffic drives in the town it is given: its grid, and its asset library.

A re-drawn town (``town.redraw_every_frames``) has the asset library of its
:func:`~generator.spec.towns.library_seed`: its own by default (``assets.redraw_every_towns`` 1), the
spec seed's with ``assets.redraw_every_towns`` null. Either way a car driving past is one of the models
parked in that town. (The moving fleet once came from a library of the town's seed while the parked
cars came from the shared one.)
"""

from __future__ import annotations

import numpy as np
import pytest

from generator.layout import build_scene
from generator.spec.load import parse_spec
from generator.spec.towns import town_spec
from generator.traffic import build_world

DOC = {"name": "redrawn_small_town", "seed": 7,
       "town": {"blocks_x": 1, "blocks_y": 1, "block_size_m": 36, "block_size_jitter_m": 0, "margin_m": 12,
                "redraw_every_frames": 5},
       "density": {"parked_cars_per_100m": 14, "people_per_100m": 6},
       "traffic": {"cars_per_km": 30, "pedestrians_per_100m": 2.0, "standing_pedestrians_per_100m": 1.0}}


@pytest.fixture(scope="module", params=[1, None], ids=["own_library", "shared_library"])
def towns(request):
    """(base scene, town 1's scene, town 1's world, redraw_every_towns): the spec's own town and a re-drawn one."""
    doc = {**DOC, "assets": {"redraw_every_towns": request.param}}
    spec = parse_spec(doc, "redrawn_small_town.json")
    town1 = town_spec(spec, 1)
    scene1 = build_scene(town1)
    return build_scene(spec), scene1, build_world(town1, scene1, 2.0), request.param


def _same_mesh(a, b) -> bool:
    return (np.array_equal(a.vertices, b.vertices) and np.array_equal(a.faces, b.faces)
            and np.array_equal(a.face_class, b.face_class))


def test_a_redrawn_towns_moving_fleet_comes_from_the_towns_asset_library(towns):
    base, scene1, world, every = towns
    assert scene1.seed != base.seed                      # a town of its own ...
    parked = [k for k in world.prototypes if k.removeprefix("actor_") in scene1.prototypes]
    kinds = {k.removeprefix("actor_").split("_v")[0] for k in parked}
    assert {"car", "person"} <= kinds, f"no moving car or person shares a model with its town: {parked}"
    for key in parked:                                   # ... whose moving cars and people are its parked models
        assert _same_mesh(world.prototypes[key], scene1.prototypes[key.removeprefix("actor_")]), key
    in_base = [k for k in world.prototypes if k.removeprefix("actor_") in base.prototypes]
    same = [_same_mesh(world.prototypes[k], base.prototypes[k.removeprefix("actor_")]) for k in in_base]
    if every is None:                                    # one library for the run: the spec seed's models
        assert in_base and all(same)
    else:                                                # a fresh library: not one car of the spec seed's town
        assert not any(s for k, s in zip(in_base, same, strict=True) if "car_v" in k)


def test_the_traffic_drives_on_the_grid_and_library_the_town_was_built_from(towns):
    _, scene1, world, every = towns
    assert world.scene is scene1
    if every is None:
        assert scene1.library.seed == DOC["seed"]        # the spec's seed, not the town's
    else:
        assert scene1.library.seed not in (DOC["seed"], scene1.seed)   # the library's own seed
    for a in world.actors:                               # every moving model is the library's own mesh
        assert world.prototypes[a.prototype] is scene1.library.protos[a.prototype.removeprefix("actor_")].mesh


def test_a_vehicle_no_lane_admits_is_a_spec_error(root, monkeypatch):
    """A town whose every lane is too narrow for a requested vehicle beside its parked objects (kitti_like's
    2.75 m lanes for a bus, in some towns) refuses the spec naming the field, not with an internal error."""
    import json

    import generator.traffic.build as tb
    from generator.errors import SpecError

    doc = json.loads((root / "scenes" / "test_town.json").read_text())
    doc["traffic"] = {"cars_per_km": 0, "buses_per_km": 3}
    spec = parse_spec(doc, "buses.json")
    scene = build_scene(spec)
    monkeypatch.setattr(tb, "too_narrow", lambda graph, *a: [e.index for e in graph.lanes()])
    with pytest.raises(SpecError, match=r"buses.json.*traffic.buses_per_km.*no lane of the town is wide enough"):
        build_world(spec, scene, 10.0)
