"""Skies and light without Blender (issue 14 items 2, 3): the draws behind clouds, overcast skies, dusk
and night, how variants group into renders, and the post fx on dim renders."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from generator.errors import SpecError
from generator.spec.load import parse_spec
from generator.weather import (
    DEFAULT_TIMES,
    KINDS,
    LIT_TIMES,
    TIMES,
    draw_lighting,
    global_irradiance,
    is_overcast,
    light_level,
    render_key,
)


def test_lighting_is_deterministic_per_seed_and_frame(test_spec):
    for tod in TIMES:
        a, b = draw_lighting(test_spec, 5, tod, "clear"), draw_lighting(test_spec, 5, tod, "clear")
        assert a == b
        other = draw_lighting(dataclasses.replace(test_spec, seed=test_spec.seed + 1), 5, tod, "clear")
        assert other != a
        assert draw_lighting(test_spec, 6, tod, "clear") != a


@pytest.mark.parametrize("tod", TIMES)
def test_overcast_whenever_it_rains_or_is_foggy(test_spec, tod):
    """Rain, fog and wet ground get a closed deck; the sun and the cloud pattern are the frame's own."""
    clear = draw_lighting(test_spec, 3, tod, "clear")
    assert not clear.overcast
    lo, hi = test_spec.weather.cloud_cover
    assert lo <= clear.cloud_cover <= hi
    for kind in KINDS:
        light = draw_lighting(test_spec, 3, tod, kind)
        assert light.overcast == is_overcast(kind) == (kind != "clear")
        if light.overcast:
            assert light.cloud_cover == 1.0
        assert (light.sun_elevation_deg, light.sun_azimuth_deg, light.lit_windows, light.cloud_seed) == (
            clear.sun_elevation_deg, clear.sun_azimuth_deg, clear.lit_windows, clear.cloud_seed)


def test_sun_positions_are_those_drawn_before_clouds(test_spec):
    """The clouds have their own stream: a day's sun and a night's windows are the draws of before."""
    from generator.rng import stream

    w = test_spec.weather
    for k in range(4):
        g = stream(test_spec.seed, "frame", k, "lighting", "day")
        day = draw_lighting(test_spec, k, "day", "rain")
        assert (day.sun_elevation_deg, day.sun_azimuth_deg) == (g.uniform(*w.sun_elevation_deg),
                                                                 g.uniform(*w.sun_azimuth_deg))
        g = stream(test_spec.seed, "frame", k, "lighting", "night")
        assert draw_lighting(test_spec, k, "night").lit_windows == g.uniform(*w.lit_windows)


def test_dusk_is_a_low_sun_with_the_lights_on(test_spec):
    """Dusk: the sun low (in the spec's dusk range) at an azimuth of the spec's range, a share of the
    windows lit drawn per frame within the spec's range, and the street lamps on (the renderer and the
    post fx light lamps at the times in LIT_TIMES; the scene gets at least the lamps' light, as at
    night). Night: no sun, windows lit as at dusk; day: no window lit."""
    w = test_spec.weather
    lo, hi = w.dusk_sun_elevation_deg
    dusks = [draw_lighting(test_spec, k, "dusk") for k in range(20)]
    for dusk in dusks:
        assert lo <= dusk.sun_elevation_deg <= hi
        assert w.sun_azimuth_deg[0] <= dusk.sun_azimuth_deg <= w.sun_azimuth_deg[1]
        assert w.lit_windows[0] <= dusk.lit_windows <= w.lit_windows[1]
    assert len({d.lit_windows for d in dusks}) == len(dusks)          # a new draw every frame
    assert "dusk" in LIT_TIMES and "night" in LIT_TIMES and "day" not in LIT_TIMES
    night = draw_lighting(test_spec, 0, "night")
    assert night.sun_elevation_deg is None and w.lit_windows[0] <= night.lit_windows <= w.lit_windows[1]
    assert min(light_level(d) for d in dusks) >= light_level(night) > 0     # at least the lamps' light
    assert draw_lighting(test_spec, 0, "day").lit_windows is None


def test_light_levels_order_day_overcast_dusk_night(test_spec):
    """The scene's light (relative to a clear day): clear day > overcast day > dusk > night, and the
    overcast share of a clear day's light is that of real overcast skies (10-40 %)."""
    for k in range(6):
        day, rain = draw_lighting(test_spec, k, "day", "clear"), draw_lighting(test_spec, k, "day", "rain")
        dusk, night = draw_lighting(test_spec, k, "dusk"), draw_lighting(test_spec, k, "night")
        assert 0.1 < light_level(rain) / light_level(day) < 0.4
        assert light_level(day) > light_level(rain) > light_level(dusk) >= light_level(night) > 0
        assert light_level(night) < 2.0 ** -9  # a street lit by lamps: ~10 EV below a clear day
    assert global_irradiance(-6.0) < global_irradiance(0.0) < global_irradiance(10.0) < global_irradiance(60.0)


def test_render_keys():
    assert render_key("clear") == (False, False)
    assert render_key("fog") == (False, True)
    assert {render_key(k) for k in ("wet", "wet_fog", "rain", "rain_fog")} == {(True, True)}


def _spec_with(root, **weather):
    doc = json.loads((root / "scenes" / "test_town.json").read_text())
    doc.setdefault("weather", {}).update(weather)
    return parse_spec(doc, "town.json")


def test_times_of_day_from_the_spec(root):
    assert _spec_with(root).weather.times_of_day == DEFAULT_TIMES
    spec = _spec_with(root, times_of_day=["night", "dusk", "day"])
    assert spec.weather.times_of_day == ("night", "dusk", "day")
    from generator.jobs.variants import parse_combos

    assert {t for t, _ in parse_combos("all", spec.weather.times_of_day)} == set(TIMES)


@pytest.mark.parametrize("field,value,reason", [
    ("times_of_day", ["day", "noon"], "noon"),
    ("times_of_day", ["day", "day"], "none repeated"),
    ("times_of_day", [], "at least 1 items"),
    ("cloud_cover", [0.2, 1.5], "1.5"),
    ("dusk_sun_elevation_deg", [6, -4], "low <= high"),
    ("dusk_sun_elevation_deg", [1e308, 1e308], "got 1e\\+308"),
    ("sun_elevation_deg", [-10, 40], "got -10"),
])
def test_bad_sky_fields_are_one_line_errors(root, field, value, reason):
    with pytest.raises(SpecError, match=rf"town.json: weather\.{field}.*({reason})") as e:
        _spec_with(root, **{field: value})
    assert "\n" not in str(e.value)


def _street(h=48, w=64):
    rng = np.random.default_rng(0)
    img = rng.uniform(0.02, 0.6, (h, w, 3)).astype(np.float32)
    img[:8] = (0.9, 1.0, 1.3)
    img[10:12, 20:22] = 30.0  # a lamp
    depth = np.where(np.arange(h)[:, None] < 8, np.inf, 4.0 + np.arange(w)[None, :] / 2).astype(np.float32)
    return img, depth


@pytest.mark.parametrize("tod,kind", [("day", "fog"), ("dusk", "rain_fog"), ("night", "rain"), ("night", "fog")])
def test_fog_and_rain_follow_the_scenes_light(test_spec, tod, kind):
    """Post fx on a render k times dimmer (a dimmer scene, its light level k times lower) give the same
    image k times dimmer: fog's airlight, lamp halos and rain streaks scale with the scene's light."""
    from generator.jobs.variants import weather_post
    from generator.world.rig import intrinsics

    img, depth = _street()
    k = intrinsics(90.0, img.shape[1], img.shape[0])
    a, pa = weather_post(test_spec, 3, tod, kind, img, depth, k, level=1.0)
    b, pb = weather_post(test_spec, 3, tod, kind, img * np.float32(1e-3), depth, k, level=1e-3)
    np.testing.assert_allclose(b, a * 1e-3, rtol=1e-3, atol=1e-9)
    assert pb["post_fx_light_level"] == 1e-3 and pa.keys() == pb.keys()


def test_table_two_has_a_dusk_column_only_with_dusk_images():
    from types import SimpleNamespace

    from generator.stats.images import table2

    def data(times):
        return SimpleNamespace(records=[SimpleNamespace(time_of_day=t, weather="clear") for t in times])

    assert table2(data(["day", "night"])).columns[1:-1] == ["Day", "Night"]
    t = table2(data(["day", "dusk", "night", "dusk"]))
    assert t.columns[1:-1] == ["Day", "Dusk", "Night"]
    assert t.rows[0][1:] == [1, 2, 1, 4]


def test_metadata_schema_knows_dusk():
    from generator.spec.validate import load_schema

    enum = load_schema("metadata")["properties"]["time_of_day"]["enum"]
    assert set(enum) == set(TIMES)
