"""Licence plates (issue 29 item 3): every car carries its own registration, the same for the same seed, drawn
from a built-in glyph atlas onto the plate's face; the plate keeps its class (car), material and geometry."""

from __future__ import annotations

import re

import numpy as np
import pytest

from assets_procedural.vehicle import CAR_VARIANTS, car
from generator.blender import plates as pl
from generator.labels import class_table
from generator.materials import material_table

REGISTRATION = re.compile(r"^[A-Z]{1,3} [A-Z]{1,2} [1-9][0-9]{0,3}$")


def test_a_registration_is_the_same_for_the_same_seed_and_car_and_differs_between_cars():
    a = [pl.plate_string(7, i) for i in range(200)]
    assert a == [pl.plate_string(7, i) for i in range(200)]
    assert len(set(a)) >= 195                                  # distinct cars, distinct plates
    assert a != [pl.plate_string(8, i) for i in range(200)]    # another seed, other plates
    for s in a:
        assert REGISTRATION.match(s), s
        assert len(s.replace(" ", "")) <= 8                    # German plates: at most eight characters


def test_plate_codes_spell_the_string_and_centre_it():
    codes, off = pl.plate_codes("KA AB 1234")
    assert "".join(pl.CHARSET[c] for c in codes) == "KA AB 1234" and off == 0.0
    codes, off = pl.plate_codes("B X 1")
    assert "".join(pl.CHARSET[c] for c in codes).rstrip() == "B X 1" and off == 2.5
    with pytest.raises(ValueError):
        pl.plate_codes("ÄB 1")


def test_every_glyph_has_ink_inside_its_character_box_and_none_outside():
    atlas = pl.glyph_atlas()
    h, w = pl.CELL_PX
    assert atlas.shape == (h, w * (len(pl.CHARSET) + 1), 4) and atlas.dtype == np.float32
    rows_mm = (np.arange(h) + 0.5) * (pl.INNER_MM[1] - pl.INNER_MM[0]) / h
    box = np.abs(rows_mm - (pl.INNER_MM[1] - pl.INNER_MM[0]) / 2) <= 75 / 2 + 1.0     # the 75 mm character height
    cells = []
    for i, ch in enumerate(pl.CHARSET):
        a = atlas[:, i * w:(i + 1) * w, 3]
        cells.append(a)
        if ch == " ":
            assert a.max() == 0.0
            continue
        assert 0.02 < a.mean() < 0.6, ch                        # strokes, not a blob (the hyphen: a dash)
        assert a[~box].max() < 0.05, ch                         # within the character's height
        assert a[:, :2].max() < 0.05 and a[:, -2:].max() < 0.05, ch   # a gap to the neighbouring cells
    for i in range(1, len(cells)):                               # every character reads differently
        for j in range(i + 1, len(cells)):
            assert np.abs(cells[i] - cells[j]).mean() > 0.01, (pl.CHARSET[i], pl.CHARSET[j])
    band = atlas[:, -w:]
    assert (band[..., 3] == 1.0).all() and band[..., 2].mean() > 2 * band[..., 0].mean()   # blue, opaque


@pytest.mark.parametrize("body", list(CAR_VARIANTS))
def test_the_plate_uv_spans_each_plates_outer_face_read_from_outside(body):
    m = car(np.random.default_rng(3), variant=body)
    plate = m.face_material == material_table().id("licence_plate")
    assert (m.face_class[plate] == class_table().id("car")).all()          # the plate's label stays car
    uv = pl.plate_uv(m.vertices, m.faces, plate)
    assert uv.shape == (m.n_faces, 3, 2)
    assert (uv[~plate] == 0).all()
    tri = m.vertices[m.faces]
    for sign in (1.0, -1.0):
        outer = plate & (sign * tri[..., 0].mean(1) > 0) & (uv[:, :, 0] >= 0).all(1)
        assert outer.sum() == 2                                  # one quad a plate
        u, v = uv[outer, :, 0].ravel(), uv[outer, :, 1].ravel()
        assert u.min() == 0 and u.max() == 1 and v.min() == 0 and v.max() == 1
        # u runs left to right as seen from outside: +y on the front plate, -y on the rear
        y = tri[outer][..., 1].ravel()
        assert np.sign(np.corrcoef(u, y)[0, 1]) == sign
        assert (uv[plate & (sign * tri[..., 0].mean(1) > 0) & ~outer] == -1).all()   # edges and back: the frame


def test_only_cars_get_registrations():
    class Ob(dict):
        def __init__(self, cls, pid):
            super().__init__(ug_class=cls)
            self.pass_index = pid

    obs = [Ob("car", 5), Ob("truck", 6), Ob("car", 7)]
    assert pl.apply_plates(obs, seed=3) == 2
    assert "ug_plate_0" not in obs[1]
    assert obs[0]["ug_plate_off"] == pl.plate_properties(3, 5)["ug_plate_off"]
    text = "".join(pl.CHARSET[int(obs[2][f"ug_plate_{i}"])] for i in range(pl.N_CELLS)).strip()
    assert text == pl.plate_string(3, 7)


@pytest.fixture(scope="module")
def rear_plates(tmp_path_factory, test_spec):
    """Two cars of one prototype (instances 4 and 9), each seen square on its rear plate from 0.9 m, by day."""
    import dataclasses

    from generator.blender.renderer import Renderer
    from generator.geometry import pose, rect
    from generator.spec.render import load_render_config
    from generator.weather import Lighting
    from generator.world import rig
    from kits.scene_kit import make_scene

    m = car(np.random.default_rng(5), variant="hatchback")
    plate = m.face_material == material_table().id("licence_plate")
    tri = m.vertices[m.faces]
    rear = plate & (tri[..., 0].mean(1) < 0)
    x_plate, z_plate = tri[rear][..., 0].min(), tri[rear][..., 2].mean()
    ground = ("ground", rect(-5, -20, 10, 40, 0.0, "road", "asphalt"), np.eye(4), 0)
    parts = [ground] + [(f"car{i}", m, pose(0.9 - x_plate, y, 0.0), i) for i, y in ((4, 0.0), (9, 20.0))]
    cfg = dataclasses.replace(load_render_config("test"), resolution=(320, 180), samples=4)
    r = Renderer(make_scene(parts, kind=None), test_spec, cfg, tmp_path_factory.mktemp("scratch"))
    r.set_conditions(Lighting("day", sun_elevation_deg=40.0, sun_azimuth_deg=180.0))
    k = rig.intrinsics(test_spec.sensors.camera.hfov_deg, 320, 180)
    hw, hh = int(0.4 * 0.52 * k[0, 0] / 0.9), int(0.4 * 0.11 * k[0, 0] / 0.9)    # 80 % of the plate
    crop = (slice(90 - hh, 90 + hh), slice(160 - hw, 160 + hw))
    eyes = [rig.camera_extrinsics((0.0, y, z_plate), (0, 0, 0)) for y in (0.0, 20.0)]
    return [r.render(e, seed=0, light_info={}) for e in eyes], crop


@pytest.mark.blender
def test_a_rear_plate_shows_dark_characters_on_a_light_ground_and_stays_car_in_the_labels(rear_plates):
    frames, crop = rear_plates
    for f in frames:
        assert (f.labels.class_id[crop] == class_table().id("car")).all()
        lum = f.rgb[crop].mean(-1)
        light, dark = lum > 0.5 * np.percentile(lum, 95), lum < 0.25 * np.percentile(lum, 95)
        assert light.mean() > 0.4                              # the plate's ground
        assert 0.05 < dark.mean() < 0.45                        # ink: characters, the band, not a black plate
    # two cars of the same prototype carry different registrations
    a, b = (f.rgb[crop].mean(-1) for f in frames)
    assert np.abs(a - b).mean() > 0.05 * a.mean()
