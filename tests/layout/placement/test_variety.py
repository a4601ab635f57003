"""Asset variety (generator/layout/placement/variety.py): dozens of cars and people per library, drawn
from real distributions, their boxes following their meshes."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from generator.layout.placement.prototypes import Library
from generator.layout.placement.variety import (
    WHO_AGE,
    WHO_HEIGHT_M,
    car_variant,
    draw_figure,
    is_child,
    person_variants,
    variant_counts,
)
from generator.rng import stream


@pytest.fixture(scope="module")
def people(default_spec):
    return person_variants(Library(default_spec.seed, variant_counts(default_spec)), default_spec)


def test_the_default_library_holds_dozens_of_people_children_to_tall_adults(default_spec, people):
    n = default_spec.assets.variants.person
    assert len(people) == n >= 40
    assert [p.params["pose"] for p in people] == ["standing"] * (n // 2) + ["walking"] * (n - n // 2)
    kids = [p for p in people if p.params["age"] < 18]
    assert len(kids) == int(default_spec.assets.child_share * n + 1e-9)     # 6 of 48
    assert {p.params["pose"] for p in kids} == {"standing", "walking"}       # spread over both halves
    lo, hi = default_spec.heights.person_m
    adults = [p for p in people if p.params["age"] >= 18]
    assert all(lo <= p.params["height"] <= hi for p in adults)
    assert {p.params["sex"] for p in adults} == {"female", "male"}
    assert max(p.params["height"] for p in kids) < min(1.7, hi)
    for p in people:    # a standing mesh is as tall as drawn; a walker at phase 0 (both feet down, knees
        h = p.hi[2] - p.lo[2]   # bent: the lowest point of its bob) up to 5 % lower
        if p.params["pose"] == "standing":
            assert h == pytest.approx(p.params["height"], abs=1e-9)
        else:
            assert 0.95 * p.params["height"] - 1e-9 <= h <= p.params["height"] + 1e-9
    assert len({p.mesh.vertices.tobytes() for p in people}) == n             # every variant its own mesh


def test_heights_follow_age_and_sex():
    g = stream(1, "test", "figures")
    adults = [draw_figure(g, (1.2, 2.2), False) for _ in range(3000)]
    for sex, mean in (("female", 1.65), ("male", 1.78)):
        h = np.array([a["height"] for a in adults if a["sex"] == sex])
        assert h.mean() == pytest.approx(mean, abs=0.01) and 0.05 < h.std() < 0.09
    kids = [draw_figure(g, (1.55, 1.95), True) for _ in range(2000)]
    resid = [k["height"] / np.interp(k["age"], WHO_AGE, WHO_HEIGHT_M) - 1 for k in kids]
    assert abs(np.mean(resid)) < 0.005 and np.std(resid) == pytest.approx(0.045, abs=0.005)
    assert all(4 <= k["age"] <= 14 for k in kids)
    clipped = [draw_figure(g, (1.55, 1.95), False)["height"] for _ in range(500)]
    assert min(clipped) >= 1.55 and max(clipped) <= 1.95


def test_children_are_spread_evenly():
    assert sum(is_child(i, 0.14) for i in range(48)) == 6
    assert not any(is_child(i, 0.0) for i in range(48)) and all(is_child(i, 1.0) for i in range(48))


def test_cars_wrap_around_the_library_count(default_spec):
    lib = Library(default_spec.seed, {"car": 10})
    assert car_variant(lib, 13) is car_variant(lib, 3)
    assert len({car_variant(lib, i).key for i in range(30)}) == 10


def test_a_town_uses_dozens_of_car_and_person_meshes_and_boxes_follow_them(default_scene):
    for kind, at_least in (("car", 40), ("person", 30)):
        objs = [o for o in default_scene.objects if o.kind == kind]
        assert len({o.prototype for o in objs}) >= at_least, kind
        for o in objs:                                                        # labels stay exact
            m = default_scene.prototypes[o.prototype]
            assert np.allclose(o.box.size, np.ptp(m.vertices, axis=0), atol=1e-9), o.name
    assert {o.cls for o in default_scene.objects if o.kind == "car"} == {"car"}
    assert {o.cls for o in default_scene.objects if o.kind == "person"} == {"person"}


def test_fewer_variants_give_fewer_meshes(default_spec):
    few = dataclasses.replace(default_spec, assets=dataclasses.replace(
        default_spec.assets, variants=dataclasses.replace(default_spec.assets.variants, car=6, person=6)))
    lib = Library(few.seed, variant_counts(few))
    assert len(person_variants(lib, few)) == 6 and lib.count("car", 48) == 6
