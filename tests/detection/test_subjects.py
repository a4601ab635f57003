"""Which things get a box, and a ridden two-wheeler is one box holding vehicle and rider (issue 26, item 1)."""

from __future__ import annotations

import numpy as np
import pytest

from generator import geometry as M
from generator.detection import subjects
from generator.detection.frames import points_in_box, rot_z
from generator.labels.detection import detection_classes
from generator.world.actors import Actor, Track, World
from generator.world.scene import OrientedBox, SceneModel, SceneObject


def _obj(i, name, kind, cls, inst, proto, T, mesh, attrs=None):
    v = M.apply(T, mesh.vertices)
    lo, hi = mesh.bounds()
    c = T[:3, :3] @ ((lo + hi) / 2) + T[:3, 3]
    yaw = float(np.arctan2(T[1, 0], T[0, 0]))
    assert v.shape[1] == 3
    box = OrientedBox(tuple(c), tuple(hi - lo), yaw)
    return SceneObject(i, name, kind, cls, inst, proto, T, box, None, attrs or {})


@pytest.fixture(scope="module")
def world():
    car = M.box((4.2, 1.8, 1.5), "car", "car_paint", center=(0, 0, 0.75))
    bike = M.box((1.8, 0.5, 1.0), "ridden_bicycle", "car_trim", center=(0, 0, 0.5))
    rider = M.box((0.6, 0.5, 1.0), "bicyclist", "clothing", center=(-0.2, 0, 1.3))   # sits higher, behind the bars
    bus = M.box((12.0, 2.5, 3.0), "bus", "truck_paint", center=(0, 0, 1.5))
    tree = M.box((1, 1, 5), "tree_crown", "leaves", center=(0, 0, 2.5))
    T_bike = M.pose(10.0, 5.0, 0.0, yaw=0.4)
    objs = [_obj(0, "car_0000", "car", "car", 1, "car", M.pose(0, 0, 0), car, {"placement": "parked"}),
            _obj(1, "ridden_bicycle_0000", "ridden_bicycle", "ridden_bicycle", 2, "bike", T_bike, bike),
            _obj(2, "bicyclist_0000", "bicyclist", "bicyclist", 3, "rider", T_bike, rider),
            _obj(3, "bus_0000", "bus", "bus", 4, "bus", M.pose(30, 0, 0), bus, {"placement": "bus_stop"}),
            _obj(4, "tree_0000", "tree", "tree_crown", 0, "tree", M.pose(5, 5, 0), tree)]
    scene = SceneModel(0, "t", np.zeros((2, 2)), {"car": car, "bike": bike, "rider": rider, "bus": bus, "tree": tree},
                       {}, objs, [])
    riding = M.merge([bike, rider])
    t = np.arange(0, 2.0001, 0.05)
    track = Track(0.0, 0.05, np.c_[3.0 * t, np.full_like(t, -4.0), np.zeros_like(t)], np.zeros_like(t))
    still = Track(0.0, 0.05, np.tile([[20.0, 6.0, 0.0]], (len(t), 1)), np.zeros_like(t))
    lo, hi = riding.bounds()
    actors = [Actor(0, "actor_bicyclist_0000", "bicyclist", "bicyclist", 10, "riding", tuple(hi - lo),
                    tuple((lo + hi) / 2), track),
              Actor(1, "actor_person_0001", "person", "person", 11, "car", (0.5, 0.5, 1.8), (0, 0, 0.9), still)]
    return World(scene, actors, {"riding": riding, "car": car}, {}, None, 2.0)


def test_every_thing_gets_one_subject_and_stuff_none(world):
    subs = {s.track_id: s for s in subjects(world.scene, world)}
    assert sorted(subs) == [1, 3, 4, 10, 11]                  # the tree (stuff) has none; 2 is the rider's bicycle
    assert {s.cls for s in subs.values()} <= set(detection_classes().boxes)


def test_a_parked_ridden_bicycle_is_one_box_with_its_rider(world):
    s = {s.track_id: s for s in subjects(world.scene, world)}[3]
    assert s.cls == "bicyclist" and s.instance_ids == (3, 2) and s.with_rider and s.static
    assert s.attribute(0.0) == "cycle.with_rider"
    b = s.box(0.0)
    v, _ = s.triangles(0.0)
    assert points_in_box(v, b.center, b.size, rot_z(b.yaw), 1e-9).all()   # vehicle and rider inside
    assert b.size[2] == pytest.approx(1.8) and b.size[0] == pytest.approx(1.8)
    assert b.yaw == pytest.approx(0.4)


def test_a_moving_rider_is_one_box_and_its_attributes_follow_the_world(world):
    subs = {s.track_id: s for s in subjects(world.scene, world)}
    rider, person, car, bus = subs[10], subs[11], subs[1], subs[4]
    assert rider.cls == "bicyclist" and rider.with_rider and rider.instance_ids == (10,)
    assert rider.attribute(1.0) == "cycle.with_rider" and rider.moving(1.0)
    v, a = rider.motion(1.0)
    np.testing.assert_allclose(v, [3.0, 0.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(a, 0.0, atol=1e-9)
    assert person.attribute(1.0) == "pedestrian.standing"
    assert car.attribute(0.0) == "vehicle.parked" and bus.attribute(0.0) == "vehicle.stopped"
