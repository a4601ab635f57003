"""Traffic in a town whose streets cross at an angle (generator/traffic/mapped_tracks.py): the
simulation runs on the grid and its tracks are mapped into the world, where nothing touches, every
vehicle heads where it goes and no one is faster than the simulation allowed."""

from __future__ import annotations

import numpy as np
import pytest

from generator.layout import build_scene
from generator.traffic.build import build_world
from kits.street_towns import skewed_spec as spec_with
from kits.traffic_contacts import assert_no_contact, assert_vehicles_miss_people, static_quads

TRAFFIC = {"cars_per_km": 20, "pedestrians_per_100m": 2, "cyclists_per_km": 4}


@pytest.mark.parametrize("seed, angle, roundabouts", [(3, 70.0, 0.5), (4, 60.0, 0.0)])
def test_traffic_touches_nothing_and_heads_where_it_goes(seed, angle, roundabouts):
    spec = spec_with((angle, angle), seed=seed, traffic=TRAFFIC, roundabouts=roundabouts)
    scene = build_scene(spec)
    world = build_world(spec, scene, 12.0)
    parked = static_quads(scene)
    vehicles = [a for a in world.actors if a.cls != "person"]
    people = [a for a in world.actors if a.cls == "person"]
    assert len(vehicles) > 5 and people
    for t in np.arange(0.0, 12.0, 0.2):
        assert_no_contact(world, t, parked)
        assert_vehicles_miss_people(world, t, vehicles, people)
    for a in vehicles:          # no crabbing: a moving vehicle's heading is its direction of travel
        t = np.arange(0.0, 12.0, 0.1)
        p = a.track.position(t)[:, :2]
        v = np.diff(p, axis=0)
        fast = np.linalg.norm(v, axis=1) > 0.1       # > 1 m/s
        if not fast.any():
            continue
        h = a.track.heading(t[:-1] + 0.05)
        err = np.angle(np.exp(1j * (np.arctan2(v[:, 1], v[:, 0]) - h)))[fast]
        assert np.abs(err).max() < np.radians(8), a.name
    E = world.ego.T_world_ego(np.array([0.0, 6.0, 12.0]))
    assert np.ptp(E[:, 0, 3]) + np.ptp(E[:, 1, 3]) > 5.0    # the ego drives


def test_speeds_in_the_world_are_the_simulated_ones():
    """The map stretches lengths by 1/sin(angle); the tracks are slowed to match, so no vehicle
    passes the speed limit in the world and the ego keeps its speed (at 60 degrees the unslowed
    tracks ran 15 % faster)."""
    spec = spec_with((60.0, 60.0), seed=4, traffic={"cars_per_km": 20}, speed_mps=3.0)
    world = build_world(spec, build_scene(spec), 20.0)
    t = np.arange(0.0, 20.0, 0.1)
    fastest = max(np.linalg.norm(np.diff(a.track.position(t)[:, :2], axis=0), axis=1).max() / 0.1
                  for a in world.actors)
    assert fastest <= spec.traffic.speed_limit_mps * 1.02
    ego = np.linalg.norm(np.diff(world.ego.T_world_ego(t)[:, :2, 3], axis=0), axis=1) / 0.1
    assert 0.9 * spec.paths.speed_mps < ego.max() <= spec.paths.speed_mps * 1.02     # it reaches its speed, no more
