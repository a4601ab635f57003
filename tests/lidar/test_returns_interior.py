"""A beam through a car's window (generator/lidar/returns.py, ``interiors`` in materials.yaml): it returns
from the modelled cabin the camera sees through the glass, or from nowhere, never from beyond the car."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from assets_procedural.car_body import body_shell, draw_dimensions
from assets_procedural.vehicle import car
from generator.geometry import box, pose, rect
from generator.geometry.mesh import face_normals
from generator.labels import class_table
from generator.lidar.returns import ReturnModel, optics_from_materials
from generator.lidar.scan import Scanner
from generator.lidar.sensors import load_preset
from generator.materials import material_table
from generator.world import rig
from kits.lidar_helpers import scene_of

H = 1.73
POSE = rig.mount((0, 0, H), (0, 0, 0))
CAR, INST = class_table().id("car"), 7
CABIN = {material_table().id(m) for m in ("car_interior", "car_headliner", "car_trim")}
X_CAR = 7.0  #: the car stands broadside 7 m ahead (+x), its left side to the sensor


@pytest.fixture(scope="module")
def sensor():
    s = load_preset("hdl64e")
    return dataclasses.replace(s, returns=dataclasses.replace(s.returns, model="physical", range_noise_m=0.0))


def _car(open_far_side: bool = False):
    m = car(np.random.default_rng(3), variant="suv").transformed(pose(X_CAR, 0.0, 0.0, yaw=-np.pi / 2))
    if open_far_side:  # a body with a seam: every face of the far half facing away from the sensor is gone
        centre = m.vertices[m.faces].mean(1)
        m = m.select(~((centre[:, 0] > X_CAR) & (face_normals(m)[:, 0] > 0.3)))
    return m


def _scan(sensor, car_mesh):
    ground = rect(-5, -30, 40, 30, 0.0, "road", "asphalt")
    wall = box((0.3, 30.0, 6.0), "building", "facade_plaster", center=(X_CAR + 5.0, 0.0, 3.0))
    objects = [("ground", ground, 0), ("wall", wall, 1)] + ([("car", car_mesh, INST)] if car_mesh is not None else [])
    scene = scene_of(objects)
    with Scanner(scene, sensor, threads=2, returns=ReturnModel.build(sensor, optics_from_materials(), 0)) as sc:
        return sc.scan(POSE).points


def _beyond(p, m):
    """Points beyond the car whose line of sight crossed its greenhouse: on both sides of the car, between the
    roof's ends and between the belt line and the roof (where the body is closed all round: glass or pillars)."""
    dims = draw_dimensions(np.random.default_rng(3), "suv")       # the dimensions car() draws first
    _, info = body_shell(dims, "suv")
    x0, x1 = info["xc"] + 0.15, info["xb"] - 0.15               # car frame: under the flat roof
    z0, z1 = dims["belt_z"] + 0.08, dims["H"] - 0.12
    lo, hi = m.bounds()
    world = np.stack([p["x"], p["y"], p["z"] + H], 1).astype(float)
    through = np.ones(len(p), bool)
    for x_plane in (lo[0], hi[0]):                               # the near and far sides of the car
        t = x_plane / np.maximum(world[:, 0], 1e-6)
        at = t[:, None] * world + (1 - t[:, None]) * np.array([0.0, 0.0, H])
        x_car = -at[:, 1]                                        # yaw -90 degrees: car +x is world -y
        through &= (x_car > x0) & (x_car < x1) & (at[:, 2] > z0) & (at[:, 2] < z1)
    return through & (p["x"] > hi[0] + 0.5)


@pytest.mark.parametrize("open_far_side", [False, True], ids=["closed", "seam"])
def test_a_beam_through_a_car_window_returns_from_the_cabin_or_nowhere_never_beyond(sensor, open_far_side):
    m = _car(open_far_side)
    p = _scan(sensor, m)
    lo, hi = m.bounds()
    on_car = (p["class"] == CAR) & (p["instance"] == INST)
    # the cabin the camera sees through the glass returns: seats, dashboard, headliner, door cards
    cabin = on_car & np.isin(p["material"], list(CABIN)) & (p["x"] > lo[0] + 0.1)
    assert cabin.sum() >= 20
    assert np.all(p["x"][cabin] < hi[0] - 0.1)          # inside the body, not on its far side
    # and nothing the beams through the windows meet beyond the car: the wall behind it stays dark
    assert not _beyond(p, m).any()
    # points inside the car's box are the car's
    inside = ((p["x"] > lo[0]) & (p["x"] < hi[0]) & (p["y"] > lo[1]) & (p["y"] < hi[1])
              & (p["z"] > 0.3 - H) & (p["z"] < hi[2] - H))
    assert np.all(p["class"][inside] == CAR)


def test_the_wall_behind_the_car_is_in_view_so_the_shadow_test_can_fail(sensor):
    """The control: without the car, the region behind it is full of wall points."""
    m = _car()
    assert _beyond(_scan(sensor, None), m).sum() >= 100
