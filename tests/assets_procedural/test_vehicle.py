"""Cars (assets_procedural/vehicle.py): a library asks for body types by quantile of the fleet shares."""

from __future__ import annotations

import numpy as np
import pytest

from assets_procedural.vehicle import CAR_VARIANTS, car


def _body_at(q: float) -> str:
    """The body type whose slice of the cumulative shares holds ``q`` (counted by hand)."""
    acc = 0.0
    for body, share in CAR_VARIANTS.items():
        acc += share
        if q < acc:
            return body
    return list(CAR_VARIANTS)[-1]


@pytest.mark.parametrize("n", [6, 48, 100])
def test_a_library_of_n_cars_holds_every_body_type_in_its_share(n):
    bodies = [_body_at((i + 0.5) / n) for i in range(n)]
    for body, share in CAR_VARIANTS.items():
        assert abs(bodies.count(body) - share * n) <= 1, body


@pytest.mark.parametrize("i", range(0, 48, 5))
def test_the_quantile_builds_that_body_type(i):
    q = (i + 0.5) / 48
    a = car(np.random.default_rng(i), quantile=q)
    b = car(np.random.default_rng(i), variant=_body_at(q))
    assert np.array_equal(a.vertices, b.vertices) and np.array_equal(a.faces, b.faces)


def test_a_quantile_outside_zero_to_one_is_refused():
    with pytest.raises(ValueError, match="quantile"):
        car(np.random.default_rng(0), quantile=1.0)
