"""Vehicles and people that read as real (issue 14, generator/layout/placement/appearance.py): fleet
paint and outfit distributions, people of the configured heights, parked cars in fleet paint.

No Blender: the distributions are checked on their draws. The car bodies and garments themselves
are tested in tests/assets_procedural (test_car_body.py, test_person.py).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from generator.layout.placement.appearance import Palette, appearance, fleet_paint, outfit
from generator.materials import srgb_to_linear
from generator.rng import stream

N_DRAWS = 20000


def _chi2_p(counts: np.ndarray, p: np.ndarray) -> float:
    return float(stats.chisquare(counts, counts.sum() * p).pvalue)


def test_fleet_colour_frequencies_match_the_configured_distribution():
    """Over many draws every paint's share matches appearance.yaml (chi-square, and within 1 point)."""
    fleet = appearance().fleet
    g = stream(5, "test", "fleet")
    names = [fleet_paint(g)["paint"] for _ in range(N_DRAWS)]
    counts = np.array([names.count(n) for n in fleet.names])
    assert _chi2_p(counts, fleet.p) > 1e-3
    assert np.abs(counts / N_DRAWS - fleet.p).max() < 0.01
    # the shares the issue asks for: mostly white, black, grey and silver
    share = dict(zip(fleet.names, fleet.p, strict=False))
    assert share["white"] == pytest.approx(0.25, abs=0.01) and share["black"] == pytest.approx(0.20, abs=0.01)
    assert share["grey"] + share["silver"] == pytest.approx(0.33, abs=0.01)
    assert share["blue"] == pytest.approx(0.09, abs=0.01) and share["red"] == pytest.approx(0.08, abs=0.01)


def test_a_skewed_distribution_is_followed_too():
    """The draw follows whatever the table says (not a fixed list): a 90/10 palette gives 90/10."""
    pal = Palette.from_rows([["a", 9, [255, 255, 255]], ["b", 1, [0, 0, 0]]], "test")
    g = np.random.default_rng(0)
    picks = np.array([pal.draw(g)[0] == "a" for _ in range(5000)])
    assert picks.mean() == pytest.approx(0.9, abs=0.015)


def test_paint_colour_is_its_entry_within_the_jitter_and_metallic_flag_follows_the_table():
    a = appearance()
    g = stream(1, "test", "paint")
    for _ in range(500):
        d = fleet_paint(g)
        base = a.fleet.linear[a.fleet.names.index(d["paint"])]
        assert np.all(np.abs(np.array(d["color"]) - base) <= a.fleet_jitter * base + 1e-4)
        assert d["paint_metallic"] == (1.0 if d["paint"] in a.metallic else 0.0)


def test_outfits_draw_each_garment_from_its_palette():
    a = appearance()
    g = stream(2, "test", "outfit")
    looks = [outfit(g) for _ in range(4000)]
    for k, (key, pal) in enumerate((("color", a.top), ("bottom_color", a.bottom), ("shoe_color", a.shoes),
                                    ("skin_color", a.skin), ("hair_color", a.hair))):
        names = [lk["outfit"].split("/")[k] for lk in looks]
        counts = np.array([names.count(n) for n in pal.names])
        assert _chi2_p(counts, pal.p) > 1e-3, key
        assert all(len(lk[key]) == 3 and 0 <= min(lk[key]) and max(lk[key]) <= 1 for lk in looks)
    # garments are drawn independently: top and bottom differ in most outfits
    assert np.mean([lk["color"] != lk["bottom_color"] for lk in looks]) > 0.8


def test_a_draw_takes_a_fixed_number_of_values():
    """Changing a distribution changes colours only: the generator moves on by the same amount."""
    g1, g2 = np.random.default_rng(3), np.random.default_rng(3)
    fleet_paint(g1)
    g2.random(4)
    assert g1.random() == g2.random()
    outfit(g1)
    g2.random(20)
    assert g1.random() == g2.random()


def test_srgb_to_linear_endpoints_and_mid_grey():
    assert srgb_to_linear([0, 255, 128]) == pytest.approx([0.0, 1.0, 0.2158605], abs=1e-6)


@pytest.mark.parametrize("rows,msg", [([], "is empty"), ([["a", 0, [1, 2, 3]]], "share must be > 0"),
                                      ([["a", 1, [1, 2, 300]]], "r, g, b in 0..255"),
                                      ([["a", 1, [1, 2]]], "each entry is"),
                                      ([["a", 1, [1, 2, 3]], ["a", 1, [1, 2, 3]]], "duplicate")])
def test_bad_palette_rows_are_refused_with_a_reason(rows, msg):
    with pytest.raises(ValueError, match=msg):
        Palette.from_rows(rows, "fleet.paints")


# -- people ----------------------------------------------------------------------------------------

def test_people_in_the_default_town_have_the_configured_heights_and_drawn_outfits(default_spec, default_scene):
    lo, hi = default_spec.heights.person_m
    people = default_scene.objects_of("person")
    assert len(people) > 20
    heights = np.array([p.box.size[2] for p in people])
    # adults within heights.person_m (a walker at phase 0, knees bent, up to 5 % below its stature);
    # children (assets.child_share, issue 29) shorter
    params = [default_scene.library.protos[p.prototype].params for p in people]
    child = np.array([q["age"] < 18 for q in params])
    low = np.array([1.0 if q["pose"] == "standing" else 0.95 for q in params])
    assert (heights[~child] >= low[~child] * lo - 1e-6).all() and (heights <= hi + 1e-6).all()
    assert child.any() and (heights[child] < lo).mean() > 0.5
    assert np.ptp(heights) > 0.1                                          # not one height for all
    for p in people:
        assert {"color", "bottom_color", "shoe_color", "skin_color", "hair_color"} <= set(p.attrs)
    assert len({tuple(p.attrs["color"]) for p in people}) > 0.8 * len(people)


def test_parked_cars_in_the_default_town_wear_fleet_paint(default_scene):
    cars = default_scene.objects_of("car")
    assert len(cars) > 50
    names = appearance().fleet.names
    assert all(c.attrs["paint"] in names for c in cars)
    light_or_dark = sum(c.attrs["paint"] in ("white", "black", "grey", "silver") for c in cars) / len(cars)
    assert 0.6 < light_or_dark < 0.95                                     # ~78 % of a real fleet
