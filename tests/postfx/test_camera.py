"""The camera model in post (issue 14 item 1): exposure, PSF, CA, vignetting, noise, response curve.

Numpy tests of each stage's property, then the model in the image writers with a fake renderer
(labels never change; off is bit-identical to the images without the model; 8-bit = crf(EXR
RGB)), then one Blender render of a day and a night (``-m blender``).
"""

from __future__ import annotations

import dataclasses
import itertools
import json

import numpy as np
import pytest
from PIL import Image

from generator.imaging.paths import image_dir, image_path
from generator.postfx import camera as cm
from generator.postfx.camera_crf import crf_8bit, curve, srgb_encode
from generator.postfx.filters import luminance
from generator.previews.preview import display_rgb, tonemap
from generator.rng import stream

#: A night render of a frame is at least this much darker than its day render (mean 8-bit value).
NIGHT_RATIO_8BIT = 0.5
#: ... and its EXR RGB (mean linear luminance up to the sensor's saturation, 1.0: the EXR is not
#: clipped, so a night's lamps, thousands of times the exposure's mid grey, would swamp a plain mean).
NIGHT_RATIO_LINEAR = 0.35
#: A night's scene radiance (before the camera) is at least this many EV below the day's, mean linear
#: luminance of the same frame: lamps light the street, not a bright sky (issue 14 item 3).
NIGHT_RENDER_EV_BELOW_DAY = 6.0


def _sensor_mean(rgb) -> float:
    """Mean luminance as a sensor holds it (saturating at 1.0)."""
    return float(np.minimum(luminance(rgb), 1.0).mean())


def _params(**kw) -> cm.CameraParams:
    """A camera with every effect off (override what a test looks at)."""
    base = {"time_of_day": "day", "radiance_scale_ev": 0.0, "ev_comp": 0.0, "ev_max": 2.0, "psf_share": 0.0,
            "vignetting": 0.0, "ca_scale": 0.0, "full_well_e": 1e12, "read_noise_e": 0.0,
            "crf": {"contrast": 1.3, "shoulder": 0.98, "white": 10.0, "mid_in": 0.18, "mid_out": 0.18}}
    return cm.CameraParams(**{**base, **kw})


def _street(time_of_day: str, h: int = 180, w: int = 320, seed: int = 0) -> np.ndarray:
    """A street-like linear image: sky, facades with texture, road; by night as the renders light it
    (:mod:`generator.blender.night`): the street at ~1e-5 of the day's radiance (moonlight, sky glow,
    spill), pools of lamp light on the road at ~1/1000 of the day's (60 lx against ~70 klx), a sky
    ~1e-6 and lamp glass ~1."""
    rng = np.random.default_rng(seed)
    img = np.empty((h, w, 3), np.float32)
    img[: h // 3] = (0.9, 1.1, 1.5)
    img[h // 3 : 2 * h // 3] = rng.uniform(0.05, 0.4, (1, w // 16, 1)).repeat(16, 1)[:, :w] * np.ones((h // 3, 1, 3))
    img[2 * h // 3 :] = 0.1
    if time_of_day == "night":
        img /= 1e5
        img[: h // 3] = (1e-6, 1.2e-6, 2e-6)
        for x in range(20, w, 60):
            img[2 * h // 3 :, max(0, x - 20) : x + 24] = 0.1 / 1000.0  # the pool of light under the lamp
            img[h // 3 - 6 : h // 3 - 2, x : x + 4] = (1.0, 0.8, 0.5)
    return img


# -- exposure -------------------------------------------------------------------------------

def test_a_known_radiance_maps_to_the_expected_value():
    """A clear day's metered luminance is exposed to mid grey; the response curve puts it at mid_out."""
    p = _params()
    img = np.full((90, 160, 3), cm.REFERENCE_LUMINANCE, np.float32)
    out, rec = cm.apply_camera(img, p, np.random.default_rng(0))
    assert rec["exposure"]["ev"] == pytest.approx(0.0, abs=1e-6)
    np.testing.assert_allclose(out, cm.KEY, rtol=1e-3)  # float16 rounding
    expected = int(np.clip(srgb_encode(np.array(p.crf["mid_out"])), 0, 1) * 255 + 0.5)
    assert np.all(crf_8bit(out, p.crf) == expected)

    # A scene 2 EV darker is brightened by AE_STRENGTH x 2 EV; at night the radiance scale and ev_max apply.
    out, rec = cm.apply_camera(img / 4, p, np.random.default_rng(0))
    assert rec["exposure"]["ev"] == pytest.approx(2 * cm.AE_STRENGTH)
    np.testing.assert_allclose(out, cm.KEY / 4 * 2 ** (2 * cm.AE_STRENGTH), rtol=1e-3)
    night = _params(time_of_day="night", radiance_scale_ev=-3.0, ev_max=1.5)
    out, rec = cm.apply_camera(img / 4, night, np.random.default_rng(0))
    assert rec["exposure"]["ev"] == 1.5  # wanted 0.8 x 5 EV: clamped
    np.testing.assert_allclose(out, cm.KEY / 4 * 2 ** (1.5 - 3.0), rtol=1e-3)


def test_exposure_stays_in_its_limits():
    p = _params(ev_max=9.5)
    dark = cm.meter(np.full((32, 32, 3), 1e-7, np.float32), p)
    bright = cm.meter(np.full((32, 32, 3), 1e3, np.float32), p)
    assert dark["ev"] == 9.5 and dark["ev_auto"] > 9.5 and dark["gain"] == pytest.approx(2 ** (9.5 - cm.EV_BASE_GAIN))
    assert bright["ev"] == cm.EV_MIN and bright["gain"] == 1.0
    # up to EV_BASE_GAIN the exposure time grows at base gain
    dim = cm.meter(np.full((32, 32, 3), cm.REFERENCE_LUMINANCE / 2 ** 5, np.float32), p)
    assert dim["ev"] == pytest.approx(5 * cm.AE_STRENGTH) and dim["gain"] == 1.0


def test_the_renders_need_no_radiance_scale():
    """The night stop-gap is gone: the camera sees every time of day's radiance as rendered."""
    assert set(cm.RADIANCE_SCALE_EV) == {"day", "dusk", "night"}
    assert all(v == 0.0 for v in cm.RADIANCE_SCALE_EV.values())
    # and its exposure range reaches a night street (~12 EV below a clear day in log-average)
    assert cm.RANGES["ev_max"][0] >= 8.0 and cm.EV_BASE_GAIN < cm.RANGES["ev_max"][0]


def test_metering_is_centre_weighted_and_robust_to_lamps():
    img = np.full((90, 160, 3), 0.1, np.float32)
    centre, edge = img.copy(), img.copy()
    centre[35:55, 70:90] = 1.0
    edge[:20, :20] = 1.0
    assert cm.metered_luminance(centre) > cm.metered_luminance(edge)
    lamps = img.copy()
    lamps[::15, ::15] = 1e3  # point lamps barely move a log-average
    assert cm.metered_luminance(lamps) < 3 * cm.metered_luminance(img)


@pytest.mark.parametrize("seed", range(6))
def test_night_is_darker_than_day_for_the_same_frame(seed):
    """With the renders' night/day relation (a street lit by lamps), every drawn camera keeps night at
    least NIGHT_RATIO darker than day, in the EXR and in 8 bits, though it exposes it far longer."""
    out = {}
    for tod in ("day", "night"):
        g = stream(seed, "frame", 0, "camera_model", tod, "clear")
        lin, rec = cm.apply_camera(_street(tod), cm.draw_params(g, tod), g)
        out[tod] = (_sensor_mean(lin), float(crf_8bit(lin, rec["crf"]).mean()), rec["exposure"]["ev"])
    assert out["night"][0] < NIGHT_RATIO_LINEAR * out["day"][0]
    assert out["night"][2] > out["day"][2] + 6.0
    assert out["night"][1] < NIGHT_RATIO_8BIT * out["day"][1]
    assert out["day"][1] < 170  # and day not washed out


# -- PSF, CA, vignetting -----------------------------------------------------------------------

def test_the_psf_conserves_energy_and_has_a_long_tail():
    img = np.zeros((512, 512, 3), np.float32)
    img[256, 256] = (1000.0, 500.0, 250.0)
    out = cm.psf(img, 0.05)
    np.testing.assert_allclose(out.sum((0, 1)), img.sum((0, 1)), rtol=2e-3)  # the PSF integrates to 1
    assert out.min() >= 0
    yy, xx = np.mgrid[:512, :512]
    r = np.hypot(yy - 256, xx - 256)
    far = out[..., 0][r > 20].sum() / img[..., 0].sum()
    assert 0.01 < far < 0.05  # a share of the light goes far from the source
    flat = np.full((64, 96, 3), 0.3, np.float32)
    np.testing.assert_allclose(cm.psf(flat, 0.05), flat, rtol=1e-5)  # uniform stays uniform


def test_chromatic_aberration_moves_red_and_blue_radially_and_little():
    h, w = 1080, 1920
    img = np.zeros((h, w, 3), np.float32)
    img[100:110, 100:110] = 1.0  # a patch near the top-left corner
    out = cm.chromatic_aberration(img, 0.001)
    np.testing.assert_array_equal(out[..., 1], img[..., 1])

    def centroid(ch):
        m = out[..., ch]
        yy, xx = np.mgrid[:h, :w]
        return np.array([(m * yy).sum(), (m * xx).sum()]) / m.sum()

    g, r, b = centroid(1), centroid(0), centroid(2)
    towards_centre = np.array([(h - 1) / 2, (w - 1) / 2]) - g
    assert np.dot(r - g, towards_centre) < 0 < np.dot(b - g, towards_centre)  # red outwards, blue inwards
    assert np.linalg.norm(r - g) < 1.5 and np.linalg.norm(b - g) < 1.5  # about a pixel at 1920 wide


def test_vignetting_darkens_the_corners_only():
    v = cm.vignetting_map(101, 201, 0.25)
    assert v[50, 100] == pytest.approx(1.0, abs=1e-3)
    assert v[0, 0] == pytest.approx(0.75, abs=1e-3) and v[-1, -1] == pytest.approx(0.75, abs=1e-3)
    assert v.min() == v[0, 0]


# -- noise -------------------------------------------------------------------------------------

def test_noise_variance_grows_as_exposure_falls():
    """Less light on the sensor, more noise: the relative variance (1 / SNR^2) of a grey patch
    grows as its radiance falls, the auto-exposure making up the brightness with gain."""
    p = _params(full_well_e=8000.0, read_noise_e=4.0)
    rel = []
    for L in (0.64, 0.16, 0.04, 0.01):
        out, _ = cm.apply_camera(np.full((200, 200, 3), L, np.float32), p, np.random.default_rng(1))
        rel.append(float(out.var() / out.mean() ** 2))
    assert all(a < b for a, b in itertools.pairwise(rel)), rel
    # The photon + read noise model: var = G s / Q + (G r / Q)^2 at any output level s.
    s, gain = np.full((400, 400), 0.2, np.float32), 4.0
    noisy = cm.sensor_noise(s, gain, 8000.0, 4.0, np.random.default_rng(2))
    assert noisy.var() == pytest.approx(gain * 0.2 / 8000 + (gain * 4 / 8000) ** 2, rel=0.03)
    # At the same output level, the variance grows with the gain the exposure needed.
    low = cm.sensor_noise(s, 1.0, 8000.0, 4.0, np.random.default_rng(2))
    assert low.var() < noisy.var() / 3


# -- response curve ------------------------------------------------------------------------------

def test_the_response_curve_is_a_monotone_s_curve_through_mid_grey():
    crf = {"contrast": 1.4, "shoulder": 0.97, "white": 8.0, "mid_in": 0.18, "mid_out": 0.17}
    x = np.geomspace(1e-4, 20, 500)
    y = curve(x, crf)
    assert np.all(np.diff(y) >= 0)
    assert curve(np.array([0.18]), crf)[0] == pytest.approx(0.17)
    assert curve(np.array([8.0, 20.0]), crf).tolist() == [1.0, 1.0]
    assert curve(np.array([0.01]), crf)[0] < 0.01  # the toe: shadows darker than linear
    rgb = np.array([[[0.0, 0.18, 8.0], [np.nan, -1.0, np.inf]]], np.float32)
    assert crf_8bit(rgb, crf).tolist() == [[[0, int(srgb_encode(0.17) * 255 + 0.5), 255], [0, 0, 255]]]


# -- determinism ---------------------------------------------------------------------------------

def test_deterministic_per_seed_and_distinct_per_image():
    img = _street("day")

    def run(seed, k=0, kind="clear"):
        g = stream(seed, "frame", k, "camera_model", "day", kind)
        return cm.apply_camera(img, cm.draw_params(g, "day"), g)

    a, b = run(3), run(3)
    np.testing.assert_array_equal(a[0], b[0])
    assert a[1] == b[1]
    for other in (run(4), run(3, k=1), run(3, kind="fog")):
        assert other[1]["params"] != a[1]["params"]
        assert not np.array_equal(other[0], a[0])


def test_parameters_stay_in_their_ranges():
    for i in range(200):
        p = cm.draw_params(stream(0, "frame", i, "camera_model", "night", "rain"), "night")
        for name, (lo, hi) in cm.RANGES.items():
            assert lo <= abs(getattr(p, name)) <= hi, (name, getattr(p, name))
        assert p.radiance_scale_ev == cm.RADIANCE_SCALE_EV["night"]


# -- in the writers ------------------------------------------------------------------------------

class _Labels:
    def __init__(self, h, w):
        self.class_id = np.zeros((h, w), np.uint8)
        self.class_id[h // 2 :] = 1
        self.class_id[: h // 4] = len(_class_names()) - 1
        self.instance = np.zeros((h, w), np.uint32)
        self.instance[h // 2 :, : w // 4] = 7
        self.depth = np.where(np.arange(h)[:, None] < h // 4, np.inf, 5.0 + np.arange(w)[None, :] / 4).astype(
            np.float32
        )
        self.seconds = {"real_pass": 0.01, "label_pass": 0.02}


def _class_names():
    from generator.labels import class_table

    return class_table().names


class _FakeRenderer:
    """What :func:`generator.jobs.variants.render_frame` asks of a renderer, without Blender."""

    device, blender_version = "cpu", None

    def __init__(self, h, w):
        from generator.world.rig import intrinsics

        self.k, self.h, self.w, self.tod = intrinsics(90.0, w, h), h, w, "day"

    def place_camera(self, T):
        pass

    def render_labels(self):
        return _Labels(self.h, self.w)

    def set_conditions(self, light, wetness, puddles):
        self.tod = light.time_of_day
        return {"wetness": wetness}

    def render_rgb(self, seed):
        return _street(self.tod, self.h, self.w, seed=0), 0.5


def _render(tmp_path, test_spec, on: bool, combos):
    from generator.jobs.variants import render_frame
    from generator.spec.render import load_render_config
    from generator.world.rig import Frame

    cfg = dataclasses.replace(load_render_config("test"), resolution=(160, 96), camera_model=on)
    frame = Frame(3, 0.0, 0.0, np.eye(4), (0.0, 0.0, 0.0), np.eye(4))
    out = tmp_path / ("on" if on else "off")
    render_frame(_FakeRenderer(96, 160), test_spec, cfg, frame, out, combos)
    return image_dir(out, frame.index)


COMBOS = [("day", "clear"), ("night", "clear"), ("day", "fog"), ("night", "rain")]


@pytest.fixture(scope="module")
def written(tmp_path_factory, test_spec):
    tmp = tmp_path_factory.mktemp("camera")
    return _render(tmp, test_spec, False, COMBOS), _render(tmp, test_spec, True, COMBOS)


def _read(images, tod, kind):
    from generator.imaging.exr import read_exr

    name = f"000003_{tod}_{kind}"
    return (read_exr(images / f"{name}.exr"), json.loads((images / f"{name}.json").read_text()),
            np.asarray(Image.open(images / f"{name}_preview.png")))


@pytest.mark.parametrize("tod,kind", COMBOS)
def test_labels_masks_and_depth_never_change(written, tod, kind):
    (off, _, _), (on, meta, _) = _read(written[0], tod, kind), _read(written[1], tod, kind)
    np.testing.assert_array_equal(on.class_id, off.class_id)
    np.testing.assert_array_equal(on.instance, off.instance)
    np.testing.assert_array_equal(on.depth, off.depth)
    assert not np.array_equal(on.rgb, off.rgb)
    assert meta["camera_model"]["params"]["time_of_day"] == tod


@pytest.mark.parametrize("tod,kind", COMBOS)
def test_off_is_bit_identical_to_no_camera_model(written, test_spec, tod, kind):
    """Off: the EXR RGB is fog/rain's output as it was, the preview the fixed tone map, no record."""
    from generator.jobs.variants import camera_post, weather_post
    from generator.spec.render import load_render_config
    from generator.weather import draw_lighting, light_level

    img, meta, png = _read(written[0], tod, kind)
    r = _FakeRenderer(96, 160)
    light = draw_lighting(test_spec, 3, tod, kind)
    r.set_conditions(light, 0.0, 0.0)
    rgb, _ = r.render_rgb(0)
    post, _ = weather_post(test_spec, 3, tod, kind, rgb, r.render_labels().depth, r.k, level=light_level(light))
    np.testing.assert_array_equal(img.rgb, post.astype(np.float16).astype(np.float32))
    np.testing.assert_array_equal(png[:96, :160], tonemap(post))
    assert "camera_model" not in meta and "camera_model" not in meta["render"]
    cfg = load_render_config("test")
    same, rec = camera_post(test_spec, cfg, 3, tod, kind, post)
    assert same is post and rec is None
    assert display_rgb(post, None).tobytes() == tonemap(post).tobytes()


def test_off_keeps_the_config_hash_of_a_config_without_the_switch(tmp_path, root):
    from generator.spec.render import load_render_config

    text = (root / "render_configs" / "test.yaml").read_text()
    lines = [ln for ln in text.splitlines() if not ln.startswith("camera_model")]
    (tmp_path / "old.yaml").write_text("\n".join(lines) + "\n")
    old, new = load_render_config(tmp_path / "old.yaml"), load_render_config("test")
    assert old.camera_model is False and new.config_hash == old.config_hash
    on = dataclasses.replace(new, camera_model=True)
    assert on.to_dict()["camera_model"] is True
    assert load_render_config("preview").camera_model and load_render_config("paper").camera_model


@pytest.mark.parametrize("tod,kind", COMBOS)
def test_on_8bit_is_the_response_curve_of_the_exr_rgb(written, tod, kind):
    from generator.imaging.metadata import validate_metadata

    img, meta, png = _read(written[1], tod, kind)
    assert validate_metadata(meta) == []
    cam = meta["camera_model"]
    np.testing.assert_array_equal(png[:96, :160], crf_8bit(img.rgb, cam["crf"]))
    assert meta["timings_s"]["camera_model"] >= 0


def test_on_night_is_darker_than_day_in_the_files(written):
    day, dmeta, dpng = _read(written[1], "day", "clear")
    night, nmeta, npng = _read(written[1], "night", "clear")
    assert _sensor_mean(night.rgb) < NIGHT_RATIO_LINEAR * _sensor_mean(day.rgb)
    assert npng[:96, :160].mean() < NIGHT_RATIO_8BIT * dpng[:96, :160].mean()
    assert nmeta["camera_model"]["exposure"]["gain"] > dmeta["camera_model"]["exposure"]["gain"]


def test_a_stereo_pair_is_one_camera_with_two_sensors(test_spec):
    from generator.jobs.variants import camera_post
    from generator.spec.render import load_render_config

    cfg = dataclasses.replace(load_render_config("test"), camera_model=True)
    img = _street("day")
    left, l_rec = camera_post(test_spec, cfg, 4, "day", "clear", img, ("stereo",), (2,))
    right, r_rec = camera_post(test_spec, cfg, 4, "day", "clear", img * 1.5, ("stereo",), (3,), l_rec["exposure"])
    assert l_rec["params"] == r_rec["params"] and l_rec["crf"] == r_rec["crf"]
    assert r_rec["exposure"] == l_rec["exposure"]  # exposed as the left camera metered
    assert not np.array_equal(left, right / 1.5)


# -- a real render ---------------------------------------------------------------------------------

@pytest.mark.blender
def test_rendered_night_is_darker_than_day_and_labels_match_off(tmp_path_factory, tmp_path, root):
    from generator.cli import main
    from generator.imaging.exr import read_exr
    from kits.rendered_frame import all_variants, render_args

    cfg = tmp_path / "test_camera.yaml"
    cfg.write_text(
        (root / "render_configs" / "test.yaml").read_text().replace("camera_model: false", "camera_model: true")
    )
    assert main(render_args(root, tmp_path / "on", "day:clear,night:clear", str(cfg))) == 0
    # off: the test preset's render of frame 3 in every variant, made once for the render tests
    outs = {"on": tmp_path / "on", "off": all_variants(tmp_path_factory, root).path()}
    imgs = {(n, t): read_exr(image_path(outs[n], f"000003_{t}_clear", ".exr")) for n in outs for t in ("day", "night")}
    pngs = {t: np.asarray(Image.open(image_path(outs["on"], f"000003_{t}_clear", "_preview.png")))[:64, :96]
            for t in ("day", "night")}
    # the render itself (camera off: the EXR is the scene radiance) is physically dim at night
    ratio = luminance(imgs["off", "night"].rgb).mean() / luminance(imgs["off", "day"].rgb).mean()
    assert ratio < 2.0 ** -NIGHT_RENDER_EV_BELOW_DAY, ratio
    assert _sensor_mean(imgs["on", "night"].rgb) < NIGHT_RATIO_LINEAR * _sensor_mean(imgs["on", "day"].rgb)
    assert pngs["night"].mean() < NIGHT_RATIO_8BIT * pngs["day"].mean()
    for t in ("day", "night"):
        np.testing.assert_array_equal(imgs["on", t].class_id, imgs["off", t].class_id)
        np.testing.assert_array_equal(imgs["on", t].depth, imgs["off", t].depth)
        np.testing.assert_array_equal(imgs["on", t].instance, imgs["off", t].instance)
