"""Fog and rain in post-processing: Koschmieder's law, day/night airlight, lamp halos, rain
streaks and lens drops, and that neither ever touches masks or depth."""

from __future__ import annotations

import numpy as np
import pytest

from generator.imaging.exr import LabelledImage, read_exr, write_exr
from generator.postfx.filters import block_mean, blur_wide, upsample
from generator.postfx.fog import DAY_AIRLIGHT, NIGHT_AIRLIGHT, airlight_for, apply_fog, beta_from_visibility, fog_image
from generator.postfx.rain import apply_rain, rain_image, streak_alpha, streak_radiance
from generator.rng import stream

H, W = 90, 160


def street_like(time_of_day: str = "day", h: int = H, w: int = W, seed: int = 0):
    """(rgb, depth): textured ground with a depth ramp, a wall band, sky on top; lamps at night."""
    g = np.random.default_rng(seed)
    rows = np.arange(h, dtype=np.float32)[:, None]
    depth = np.where(rows > h * 0.45, 1.5 * (w / 2) / np.maximum(rows - h * 0.45, 1e-3), np.inf)
    depth = np.broadcast_to(depth, (h, w)).astype(np.float32).copy()
    wall = (rows < h * 0.45) & (rows > h * 0.15)
    depth = np.where(np.broadcast_to(wall, (h, w)), np.linspace(8, 60, w, dtype=np.float32)[None, :], depth)
    level = 0.3 if time_of_day == "day" else 0.01
    rgb = (level * (0.5 + g.random((h, w, 3)))).astype(np.float32)
    rgb[~np.isfinite(depth)] = (0.9, 1.0, 1.2) if time_of_day == "day" else (0.004, 0.005, 0.009)
    if time_of_day == "night":
        rgb[19:24, 39:44] = 30.0  # a lamp on the wall
    return rgb, depth


# -- fog ---------------------------------------------------------------------------------

def test_fog_pulls_far_pixels_toward_airlight_monotonically():
    a = np.array([0.6, 0.62, 0.66], np.float32)
    j = np.full((1, 50, 3), [0.1, 0.3, 0.9], np.float32)  # one colour J at depths 1..1000 m
    d = np.geomspace(1, 1000, 50).astype(np.float32)[None, :]
    out = apply_fog(j, d, beta_from_visibility(100.0), a)
    dist = np.abs(out - a).sum(-1)[0]
    step = np.diff(dist)
    assert np.all(step <= 0), "|I - A| must never grow with depth for a fixed J"
    assert np.all(step[dist[:-1] > 1e-5] < 0), "... and must shrink strictly until it reaches A"
    assert dist[0] > 0.9 * np.abs(j[0, 0] - a).sum() and dist[-1] < 1e-3


def test_sky_becomes_the_airlight_and_zero_beta_changes_nothing():
    rgb, depth = street_like("day")
    air = airlight_for("day")
    out = apply_fog(rgb, depth, 0.05, air)
    sky = ~np.isfinite(depth)
    np.testing.assert_allclose(out[sky], np.broadcast_to(DAY_AIRLIGHT, out[sky].shape), rtol=1e-6)
    np.testing.assert_array_equal(apply_fog(rgb, depth, 0.0, air), rgb)


def rms_contrast(rgb: np.ndarray) -> float:
    lum = rgb @ np.array([0.2126, 0.7152, 0.0722], np.float32)
    return float(lum.std() / lum.mean())


def test_denser_fog_means_less_contrast():
    rgb, depth = street_like("day")
    c = [rms_contrast(fog_image(rgb, depth, v, "day")[0]) for v in (1000.0, 250.0, 80.0, 30.0)]
    assert c[0] < rms_contrast(rgb) and all(a > b for a, b in zip(c, c[1:], strict=False)), c


def test_night_airlight_darker_than_day():
    assert np.mean(NIGHT_AIRLIGHT) < 0.1 * np.mean(DAY_AIRLIGHT)
    rgb, depth = street_like("day")
    day = fog_image(rgb, depth, 60.0, "day")[0]
    night = fog_image(*street_like("night"), 60.0, "night")[0]
    assert night.mean() < 0.2 * day.mean()


def test_lamps_lift_the_night_airlight_locally():
    rgb, depth = street_like("night")
    air = airlight_for("night", rgb, beta_from_visibility(50.0), depth)
    field = air.field()
    assert field.shape == rgb.shape
    near, far = field[15:28, 35:48].mean(), field[20:23, 140:150].mean()
    assert near > 5 * far and far == pytest.approx(np.mean(NIGHT_AIRLIGHT), rel=0.5)
    assert air.to_dict()["lamp_halo"]["emitter_pixels"] == 25
    thin = airlight_for("night", rgb, beta_from_visibility(2000.0), depth).field()[15:28, 35:48].mean()
    assert thin < near, "thin fog must give a fainter halo than dense fog"
    # Day: no halo, and a render without lamps gets none at night either.
    assert airlight_for("day", rgb, 0.05, depth).glow is None
    dark = street_like("night")[0]
    dark[19:24, 39:44] = 0.01
    assert airlight_for("night", dark, 0.05, depth).glow is None


def test_fog_image_reports_its_parameters():
    rgb, depth = street_like("night")
    _, p = fog_image(rgb, depth, 80.0, "night")
    assert p["model"] == "koschmieder" and p["visibility_m"] == 80.0
    assert p["beta_per_m"] == pytest.approx(3.912 / 80.0)
    assert p["airlight_rgb"] == pytest.approx(list(NIGHT_AIRLIGHT)) and p["lamp_halo"]["emitter_pixels"] > 0


def test_blur_helpers_preserve_mean_and_shape():
    g = np.random.default_rng(3)
    img = g.random((101, 203, 3)).astype(np.float32)
    for f in (1, 3, 7):
        small = block_mean(img, f)
        assert small.shape == (-(-101 // f), -(-203 // f), 3)
        assert upsample(small, f, 101, 203).shape == img.shape
    const = np.full((50, 70), 0.25, np.float32)
    np.testing.assert_allclose(upsample(block_mean(const, 4), 4, 50, 70), const, rtol=1e-6)
    b = blur_wide(img, 12.0)
    assert b.shape == img.shape and abs(b.mean() - img.mean()) < 0.01 and b.std() < 0.2 * img.std()


# -- rain --------------------------------------------------------------------------------

def changed(a: np.ndarray, b: np.ndarray) -> int:
    return int(np.count_nonzero(np.abs(a - b).max(-1) > 1e-3))


def test_rain_changes_pixels_more_with_more_rain():
    rgb, depth = street_like("day", 180, 320)
    counts = [changed(rgb, apply_rain(rgb, depth, r, stream(7, "frame", 0, "rain", "day", "rain"), "day"))
              for r in (1.0, 10.0, 50.0)]
    assert 0 < counts[0] < counts[1] < counts[2], counts
    _, p1 = rain_image(rgb, depth, 2.0, np.random.default_rng(1), "day")
    _, p2 = rain_image(rgb, depth, 40.0, np.random.default_rng(1), "day")
    assert p2["streaks"] > 3 * p1["streaks"] and p2["median_drop_mm"] > p1["median_drop_mm"]


def test_rain_is_reproducible_per_rng_and_differs_between_seeds():
    rgb, depth = street_like("night", 180, 320)
    a = apply_rain(rgb, depth, 20.0, stream(1, "frame", 3, "rain", "night", "rain"), "night")
    b = apply_rain(rgb, depth, 20.0, stream(1, "frame", 3, "rain", "night", "rain"), "night")
    c = apply_rain(rgb, depth, 20.0, stream(1, "frame", 4, "rain", "night", "rain"), "night")
    np.testing.assert_array_equal(a, b)
    assert changed(a, c) > 100


def test_streaks_are_occluded_by_near_geometry():
    depth = np.full((120, 200), np.inf, np.float32)
    depth[:, :100] = 0.3  # a wall 0.3 m away, nearer than any drop, fills the left half
    alpha, p = streak_alpha(depth, 40.0, np.random.default_rng(5), 100.0, 1 / 60)
    assert p["streaks"] > 500
    assert alpha[:, :97].max() == 0.0 and np.count_nonzero(alpha[:, 103:] > 0.01) > 1000
    # At 3 m the wall hides only the drops behind it: same draws, less opacity on the left only.
    free = streak_alpha(np.full_like(depth, np.inf), 40.0, np.random.default_rng(5), 100.0, 1 / 60)[0]
    depth[:, :100] = 3.0
    behind = streak_alpha(depth, 40.0, np.random.default_rng(5), 100.0, 1 / 60)[0]
    assert np.all(behind <= free + 1e-6)
    assert 0 < behind[:, :97].sum() < 0.95 * free[:, :97].sum()
    np.testing.assert_allclose(behind[:, 103:], free[:, 103:], atol=1e-6)


def test_night_streaks_are_dark_except_near_lamps():
    rgb, depth = street_like("night", 180, 320)
    s = streak_radiance(rgb, "night").mean(-1)
    near_lamp, far_away = s[15:30, 35:50].mean(), s[120:, 240:].mean()
    assert near_lamp > 3 * far_away
    day = streak_radiance(street_like("day", 180, 320)[0], "day").mean(-1)
    assert far_away < 0.1 * day[120:, 240:].mean()


# -- masks and depth are never touched -------------------------------------------------------

def test_fog_and_rain_leave_inputs_masks_and_depth_untouched(tmp_path):
    rgb, depth = street_like("night", 120, 200)
    class_id = np.random.default_rng(0).integers(0, 20, depth.shape).astype(np.uint8)
    instance = np.random.default_rng(1).integers(0, 5, depth.shape).astype(np.uint32)
    src = tmp_path / "src.exr"
    write_exr(src, LabelledImage(rgb, class_id, instance, depth))
    im = read_exr(src)
    rgb0, depth0, cls0 = im.rgb.copy(), im.depth.copy(), im.class_id.copy()
    fogged, _ = fog_image(im.rgb, im.depth, 60.0, "night")
    rained = apply_rain(fogged, im.depth, 30.0, np.random.default_rng(3), "night")
    for arr, ref in ((im.rgb, rgb0), (im.depth, depth0), (im.class_id, cls0)):
        np.testing.assert_array_equal(arr, ref)  # inputs not modified in place
    assert rained.dtype == np.float32 and rained.shape == rgb0.shape and changed(rained, rgb0) > 0
    out = tmp_path / "out.exr"
    write_exr(out, LabelledImage(rained, im.class_id, im.instance, im.depth))
    back = read_exr(out)
    np.testing.assert_array_equal(back.class_id, class_id)
    np.testing.assert_array_equal(back.instance, instance)
    assert back.depth.tobytes() == depth.astype(np.float32).tobytes()


def test_bad_arguments_raise():
    rgb, depth = street_like("day")
    with pytest.raises(ValueError):
        apply_fog(rgb, depth[:-1], 0.01, DAY_AIRLIGHT)
    with pytest.raises(ValueError):
        airlight_for("noon")
    with pytest.raises(ValueError):
        apply_rain(rgb, depth, -1.0, np.random.default_rng(0), "day")
    with pytest.raises(ValueError):
        beta_from_visibility(0.0)
