"""A car's cabin (assets_procedural/vehicle_interior.py): inside the body, seen through the glass, the car's
class on every face, and a modest triangle budget."""

from __future__ import annotations

import numpy as np
import pytest
from trimesh.ray.ray_pyembree import RayMeshIntersector

from assets_procedural.car_body import BODY_TYPES, body_shell, draw_dimensions
from assets_procedural.vehicle import car
from assets_procedural.vehicle_interior import car_interior
from generator.geometry.mesh import Mesh
from generator.labels import class_table
from generator.materials import material_table

MATS = material_table()
CABIN = [MATS.id(m) for m in ("car_interior", "car_headliner")]
CASES = [(body, seed) for body in BODY_TYPES for seed in range(3)]


def _parts(body: str, seed: int) -> tuple[Mesh, Mesh]:
    p = draw_dimensions(np.random.default_rng(seed), body)
    shell, info = body_shell(p, body)
    return shell, car_interior(p, info)


@pytest.mark.parametrize("body,seed", CASES)
def test_the_cabin_lies_inside_the_body_shell(body, seed):
    shell, cabin = _parts(body, seed)
    tm = shell.to_trimesh()
    assert tm.is_watertight
    assert tm.contains(cabin.vertices).all()
    # and fills it: seats front and rear, the dashboard ahead of them, something under the roof
    lo, hi = cabin.bounds()
    s_lo, s_hi = shell.bounds()
    assert hi[0] - lo[0] > 0.38 * (s_hi[0] - s_lo[0])  # a pickup: the cab ahead of its bed
    assert np.isin(cabin.face_material, MATS.id("car_headliner")).any()


@pytest.mark.parametrize("body,seed", CASES)
def test_every_face_is_the_cars_and_the_cabin_is_a_few_hundred_triangles(body, seed):
    m = car(np.random.default_rng(seed), variant=body)
    assert (m.face_class == class_table().id("car")).all()
    _, cabin = _parts(body, seed)
    assert 120 <= cabin.n_faces <= 260
    assert m.n_faces <= 1800
    for name in ("car_glass", "car_interior", "car_headliner", "car_trim", "rubber", "wheel_rim", "headlight",
                 "taillight", "licence_plate"):
        assert (m.face_material == MATS.id(name)).any(), name


@pytest.mark.parametrize("body", list(BODY_TYPES))
def test_looking_through_a_side_window_shows_the_cabin_not_the_far_window(body):
    """Rays from the sidewalk at eye height through the side glass: they first meet the glass, and many then a
    cabin part (a seat, the headliner, a door card) before the far side's glass or body."""
    m = car(np.random.default_rng(1), variant=body)
    rays = RayMeshIntersector(m.to_trimesh())
    glass = m.face_material == MATS.id("car_glass")
    centre = m.vertices[m.faces].mean(1)
    side = glass & (centre[:, 1] > 0.5) & (np.abs(centre[:, 0]) < 1.0)     # left side windows, mid-car
    targets = centre[side]
    eye = np.array([0.0, 4.0, 1.6])
    d = targets - eye
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    inside = CABIN + [MATS.id("car_trim")]
    loc, ray, tri = rays.intersects_location(np.repeat(eye[None], len(d), 0), d, multiple_hits=True)
    seen = 0
    for r in range(len(d)):
        at = ray == r
        hits = m.face_material[tri[at][np.argsort(np.linalg.norm(loc[at] - eye, axis=1))]]
        assert hits[0] == MATS.id("car_glass")
        seen += bool(len(hits) > 1 and hits[1] in inside)
    assert len(d) >= 4 and seen >= 0.25 * len(d)  # the rest: the far window (and what lies beyond)
