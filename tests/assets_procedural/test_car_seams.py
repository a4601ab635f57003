"""Panel seams of car bodies (issue 29 item 3): every body type marks its doors, handles, bumpers and lids where
a real car has them, on the body, in the order a car has them."""

from __future__ import annotations

import numpy as np
import pytest

from assets_procedural.car_seams import SEAM_ANCHORS
from assets_procedural.vehicle import CAR_VARIANTS, car
from generator.materials import material_table


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("body", list(CAR_VARIANTS))
def test_seams_lie_on_the_body_in_a_cars_order(body, seed):
    m = car(np.random.default_rng(seed), variant=body)
    a = m.anchors
    assert all(k in a for k in SEAM_ANCHORS)
    (lo, hi) = m.bounds()
    doors, (sill, belt) = a["seam/doors"][:, 0], a["seam/band"][:, 2]
    # front door's leading edge, then the seam between the doors, then the rear door's trailing edge
    assert doors[0] - doors[1] > 0.45 and doors[1] - doors[2] > 0.5, doors
    assert doors[0] < a["seam/bumpers"][0, 0] - 0.3                       # the front door starts behind the arch
    pillar = np.isin(m.face_material, [material_table().id("car_trim")]) & (m.vertices[m.faces][..., 2].min(1) > belt)
    xs = m.vertices[m.faces[pillar]][..., 0].mean(1)
    assert np.abs(xs - doors[1]).min() < 0.06                              # between the doors stands the B-pillar
    assert lo[0] + 0.5 < doors[2] and doors[0] < hi[0] - 0.7
    assert 0.2 < sill < belt < hi[2] - 0.3
    hx, hz = a["seam/handles"][:, 0], a["seam/handles"][:, 2]
    assert doors[1] < hx[0] < doors[0] and doors[2] < hx[1] < doors[1]     # each handle on its own door
    assert np.all((sill < hz) & (hz < belt))
    # the handles are near each door's rear edge, where a hand reaches for them
    assert hx[0] - doors[1] < 0.3 and hx[1] - doors[2] < 0.3
    (xf, _, zf), (xr, _, zr) = a["seam/bumpers"]
    assert doors[0] < xf < hi[0] and lo[0] < xr < doors[2]                 # the bumpers end at the wheel arches
    tail_lamps = a["taillight"][:, 2]
    assert 0.25 < zf < belt and 0.25 < zr < tail_lamps.min()              # below the lamps, above the sills
    (x_hood, y_hood, _), (x_boot, y_boot, _) = a["seam/lids"]
    assert doors[0] < x_hood < hi[0] and lo[0] < x_boot < doors[2]
    assert 0.5 * hi[1] < y_hood < hi[1] and 0.5 * hi[1] < y_boot < hi[1]


def test_seam_points_sit_on_the_painted_shell():
    m = car(np.random.default_rng(4), variant="estate")
    body = m.face_material == material_table().id("car_body")
    centres = m.vertices[m.faces[body]].mean(1)
    for x, _, z in m.anchors["seam/doors"]:
        near = centres[(np.abs(centres[:, 0] - x) < 0.25) & (np.abs(centres[:, 2] - z) < 0.15)]
        assert len(near) and np.abs(near[:, 1]).max() > 0.85 * m.bounds()[1][1]   # the car's side, not inside it
