"""A car's glass in the camera (issue 29 item 3): transparent where a cabin is modelled behind it (class car,
``interiors`` in materials.yaml), dark and glossy elsewhere (a truck's); the label pass still draws the
pane as its vehicle, and the masks still partition every pixel."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from generator.geometry import box, polygon, pose, rect
from generator.labels import class_table
from generator.weather import Lighting
from generator.world import rig
from kits.scene_kit import make_scene

pytestmark = pytest.mark.blender

CLS = class_table()
CAR, TRUCK, BUILDING = CLS.id("car"), CLS.id("truck"), CLS.id("building")


@pytest.fixture(scope="module")
def panes(tmp_path_factory, test_spec):
    """A white wall 10 m ahead; 5 m ahead, the left half of the view behind a car's pane, the right half
    behind a truck's (the same material, ``car_glass``)."""

    def pane(y0, y1, cls):
        q = np.array([[5.0, y0, -0.5], [5.0, y1, -0.5], [5.0, y1, 2.5], [5.0, y0, 2.5]])
        return polygon(q, cls, "car_glass", (-1.0, 0.0, 0.0))

    parts = [("car_pane", pane(0.05, 4.0, "car"), np.eye(4), 1),
             ("truck_pane", pane(-4.0, -0.05, "truck"), np.eye(4), 2)]
    return _render_by_day(parts, 10.15, 1.0, test_spec, tmp_path_factory)


def test_a_cars_glass_shows_what_is_behind_it_a_trucks_does_not(panes):
    lab = panes.labels
    car, truck = lab.class_id == CAR, lab.class_id == TRUCK
    assert car.sum() > 500 and truck.sum() > 500
    # the label pass draws each pane as its vehicle, at the pane's depth (not the wall's)
    assert np.median(lab.depth[car]) < 7.0 and np.median(lab.depth[truck]) < 7.0
    lum = panes.rgb.mean(-1)
    wall = (lab.class_id == BUILDING)
    assert wall.sum() > 200
    # through the car's pane the sunlit wall shows, tinted; the truck's pane stays dark
    assert np.median(lum[car]) > 0.25 * np.median(lum[wall])
    assert np.median(lum[car]) > 1.8 * np.median(lum[truck])   # measured ~2.5x (the truck's pane mirrors the sky)


def test_the_masks_partition_every_pixel_with_glass_in_view(panes):
    cls = panes.labels.class_id
    assert cls.dtype == np.uint8 and cls.max() < len(CLS)
    masks = np.stack([cls == i for i in range(len(CLS))])
    assert (masks.sum(0) == 1).all()


@pytest.fixture(scope="module")
def parked_car(tmp_path_factory, test_spec):
    """A real car broadside 6 m ahead, by day."""
    from assets_procedural.vehicle import car

    m = car(np.random.default_rng(2), variant="sedan")
    return _render_by_day([("car", m, pose(6.0, 0.0, 0.0, yaw=np.pi / 2), 3)], 14.15, 1.5, test_spec, tmp_path_factory)


def test_a_car_with_its_cabin_is_one_solid_car_mask(parked_car):
    lab = parked_car.labels
    car = lab.class_id == CAR
    assert car.sum() > 800
    assert set(np.unique(lab.instance[car])) == {3}
    # no hole in the mask where the windows are: every column of the car's mask is one run of pixels
    cols = np.flatnonzero(car.any(0))
    for c in cols[2:-2]:
        rows = np.flatnonzero(car[:, c])
        assert rows[-1] - rows[0] + 1 == len(rows), c
    masks = np.stack([lab.class_id == i for i in range(len(CLS))])
    assert (masks.sum(0) == 1).all()


def _render_by_day(parts, wall_x, eye_z, test_spec, tmp_path_factory):
    """``parts`` on a road before a plaster wall at ``x = wall_x``, seen along +x from ``eye_z`` m up, by day,
    at the tiny test preset."""
    from generator.blender.renderer import Renderer
    from generator.spec.render import load_render_config

    ground = [("ground", rect(-5, -20, 30, 20, 0.0, "road", "asphalt"), np.eye(4), 0),
              ("wall", box((0.3, 40.0, 8.0), "building", "facade_plaster", (wall_x, 0.0, 4.0)), np.eye(4), 0)]
    cfg = dataclasses.replace(load_render_config("test"), resolution=(160, 90), samples=4)
    r = Renderer(make_scene(ground + parts, kind=None), test_spec, cfg, tmp_path_factory.mktemp("scratch"))
    r.set_conditions(Lighting("day", sun_elevation_deg=40.0, sun_azimuth_deg=180.0))
    return r.render(rig.camera_extrinsics((0.0, 0.0, eye_z), (0, 0, 0)), seed=0, light_info={})
