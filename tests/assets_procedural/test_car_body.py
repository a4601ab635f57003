"""Car body types (assets_procedural/car_body.py, vehicle.py): every body rests on its four wheels,
the bodies differ in shape as they do on the street, lamps and plates face out and stand proud of
the body, and the default mix follows its shares. Meshes checked with numpy and Embree."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats
from trimesh.ray.ray_pyembree import RayMeshIntersector

from assets_procedural import catalog
from assets_procedural.car_body import BODY_TYPES
from assets_procedural.vehicle import CAR_VARIANTS
from generator.geometry import face_normals
from generator.materials import material_table


def _chi2_p(counts: np.ndarray, p: np.ndarray) -> float:
    return float(stats.chisquare(counts, counts.sum() * p).pvalue)


def _car(body: str, seed: int):
    return catalog.build("car", np.random.default_rng(seed), variant=body)


def _of(m, name: str) -> np.ndarray:
    return m.face_material == material_table().id(name)


@pytest.mark.parametrize("body", list(CAR_VARIANTS))
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_every_body_type_rests_on_its_four_wheels(body, seed):
    """Only tyres touch the ground, at four contact points under the wheel arches, and the body
    hangs its ground clearance above it (a gap the LiDAR sees through)."""
    m = _car(body, seed)
    v = m.vertices
    low = v[:, 2] < 1e-6
    used_by_tyres = np.zeros(len(v), bool)
    used_by_tyres[np.unique(m.faces[_of(m, "rubber")])] = True
    assert low.any() and not (low & ~used_by_tyres).any()
    contacts = v[low]                                                   # each tyre touches along a line across it
    wheels = np.unique(np.c_[np.round(contacts[:, 0], 2), np.sign(contacts[:, 1])], axis=0)
    assert len(wheels) == 4
    xs = np.unique(wheels[:, 0])
    assert len(xs) == 2                                                 # two axles ...
    assert np.allclose(np.sort(contacts[contacts[:, 1] > 0, 1]), np.sort(-contacts[contacts[:, 1] < 0,
                                                                                   1]))  # ... a symmetric track
    assert np.ptp(contacts[contacts[:, 1] > 0, 1]) > 0.1                # a tyre's width on the road
    lo, hi = m.bounds()
    wheelbase = xs[1] - xs[0]
    assert 0.5 * (hi[0] - lo[0]) < wheelbase < 0.68 * (hi[0] - lo[0])  # axles near the ends, not the middle
    body_faces = ~np.isin(m.face_material, [material_table().id(x) for x in ("rubber", "wheel_rim", "chrome")])
    body_z = v[np.unique(m.faces[body_faces])][:, 2]
    clear = BODY_TYPES[body]["clear"]
    assert clear[0] - 1e-6 <= body_z.min() <= clear[1] + 0.11        # the bumpers curve up from the sills
    # a horizontal ray under the car between the axles passes through (the gap under the body)
    y = np.linspace(-0.4, 0.4, 5)
    origins = np.c_[np.full(5, xs.mean()), y, np.full(5, 0.08)] - [0, 5.0, 0]
    hit = RayMeshIntersector(m.to_trimesh()).intersects_any(origins + [0, 0, 0], np.tile([0, 1.0, 0], (5, 1)))
    assert not hit.any()


@pytest.mark.parametrize("body", list(CAR_VARIANTS))
def test_body_types_differ_in_shape_as_they_do_on_the_street(body):
    """Dimensions inside each type's real range; glass all around; the shapes that tell types apart."""
    m = _car(body, 4)
    lo, hi = m.bounds()
    L, H = hi[0] - lo[0], hi[2] - lo[2]
    t = BODY_TYPES[body]
    assert t["L"][0] - 0.05 <= L <= t["L"][1] + 0.05 and t["H"][0] - 0.01 <= H <= t["H"][1] + 0.05
    glass = m.vertices[np.unique(m.faces[_of(m, "car_glass")])]
    assert glass[:, 1].max() > 0.5 and glass[:, 1].min() < -0.5         # side windows on both sides
    assert glass[:, 0].max() > 0.2 * L / 2                              # a windscreen ahead of the middle
    shell = m.vertices[np.unique(m.faces[_of(m, "car_body") | _of(m, "car_glass")])]

    def top_within(d: float) -> float:
        return shell[shell[:, 0] < lo[0] + d, 2].max() / H

    # a sedan (boot) and a pickup (bed) stay low at the back; hatch, estate, SUV and MPV carry the
    # roof to the tail, the estate, SUV and MPV to a near-vertical tailgate
    assert (top_within(0.5) > 0.85) == (t["tail"] not in ("notch", "bed"))
    if t["tail"] == "box":
        assert top_within(0.35) > 0.85
    if t["tail"] in ("notch", "bed"):
        assert top_within(0.5) < 0.75


@pytest.mark.parametrize("body", list(CAR_VARIANTS))
def test_lamps_and_plates_face_out_and_stand_proud_of_the_body(body):
    """Looking straight at a lamp or plate face from outside, it is the first surface and the body
    lies at least 2 cm behind it (no z-fighting with the paint)."""
    m = _car(body, 4)
    n = face_normals(m)
    centre = m.vertices[m.faces].mean(1)
    for name in ("headlight", "taillight", "licence_plate"):
        out = _of(m, name) & (np.abs(n[:, 0]) > 0.99) & (n[:, 0] * centre[:, 0] > 0)
        faces = np.flatnonzero(out)
        assert len(faces) >= 4, name                                       # two lamps / two plates, 2 triangles each
        origins = centre[faces] + 0.5 * n[faces]
        loc, ray, _ = RayMeshIntersector(m.to_trimesh()).intersects_location(origins, -n[faces], multiple_hits=True)
        d = np.linalg.norm(loc - origins[ray], axis=1)
        for r in range(len(faces)):
            hits = np.sort(d[ray == r])
            assert hits[0] == pytest.approx(0.5, abs=2e-3) and hits[1] - hits[0] >= 0.0195, name


def test_default_body_mix_follows_the_shares():
    g = np.random.default_rng(9)
    names = list(CAR_VARIANTS)
    drawn = [names[int(g.choice(len(names), p=np.array(list(CAR_VARIANTS.values()))))] for _ in range(3000)]
    counts = np.array([drawn.count(n) for n in names])
    assert _chi2_p(counts, np.array(list(CAR_VARIANTS.values()))) > 1e-3
    assert sum(CAR_VARIANTS.values()) == pytest.approx(1.0)
