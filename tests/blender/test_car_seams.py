"""Panel gaps and door handles (issue 29 item 3): a car body's paint draws dark 4 mm seams where its builder marks
the doors, only there, and the labels do not change."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from assets_procedural.car_seams import SEAM_ANCHORS
from assets_procedural.vehicle import car
from generator.geometry import Mesh
from generator.labels import class_table


def test_only_car_bodies_get_seam_properties():
    from generator.blender.car_seam_shader import seam_properties

    m = car(np.random.default_rng(2), variant="sedan")
    props = seam_properties(m.anchors)
    assert props["ug_seam_on"] == (1.0,)
    doors = props["ug_seam_doors"]
    assert doors[:3] == tuple(m.anchors["seam/doors"][:, 0]) and doors[3] == m.anchors["seam/band"][0, 2]
    assert all(len(v) == 4 for k, v in props.items() if k != "ug_seam_on")
    assert seam_properties({"headlight": m.anchors["headlight"]}) == {}


def _seamed_and_plain(tmp_path_factory, test_spec, place, eye_z: float, size: tuple[int, int], sun_az: float):
    """A sedan (seed 2) with its seams at y = 0 and the same mesh without seam anchors at y = 20, each placed by
    ``place(mesh, y)`` -> (4, 4) pose and seen by a camera at (0, y, ``eye_z``) looking along +x; ``size`` pixels,
    4 samples, by day. Returns (frames, intrinsics, the seamed mesh)."""
    from generator.blender.renderer import Renderer
    from generator.geometry import rect
    from generator.spec.render import load_render_config
    from generator.weather import Lighting
    from generator.world import rig
    from kits.scene_kit import make_scene

    m = car(np.random.default_rng(2), variant="sedan")
    plain = Mesh(m.vertices, m.faces, m.face_class, m.face_material,
                 {k: v for k, v in m.anchors.items() if k not in SEAM_ANCHORS})
    ground = ("ground", rect(-5, -20, 10, 60, 0.0, "road", "asphalt"), np.eye(4), 0)
    parts = [ground] + [(f"car{i}", mesh, place(m, y), i) for i, mesh, y in ((4, m, 0.0), (9, plain, 20.0))]
    cfg = dataclasses.replace(load_render_config("test"), resolution=size, samples=4)
    r = Renderer(make_scene(parts, kind=None), test_spec, cfg, tmp_path_factory.mktemp("scratch"))
    r.set_conditions(Lighting("day", sun_elevation_deg=40.0, sun_azimuth_deg=sun_az))
    k = rig.intrinsics(test_spec.sensors.camera.hfov_deg, *size)
    frames = [r.render(rig.camera_extrinsics((0.0, y, eye_z), (0, 0, 0)), seed=0, light_info={}) for y in (0.0, 20.0)]
    return frames, k, m


@pytest.fixture(scope="module")
def side_views(tmp_path_factory, test_spec):
    """The sedan side on from 0.8 m at the seam between its doors, 10 cm above its handles; 640 x 360."""
    from generator.geometry import pose

    def place(m, y):   # yaw 90 degrees: the right side (+y) faces the camera; the car's x runs along +y
        return pose(0.8 + m.bounds()[1][1], y - m.anchors["seam/doors"][1, 0], 0.0, yaw=np.pi / 2)

    m = car(np.random.default_rng(2), variant="sedan")
    return _seamed_and_plain(tmp_path_factory, test_spec, place, m.anchors["seam/handles"][0, 2] + 0.1,
                             (640, 360), 200.0)


@pytest.mark.blender
def test_the_seam_between_the_doors_is_a_dark_line_and_nothing_else_changes(side_views):
    (seamed, plain), k, m = side_views
    cx, cy, f = int(round(k[0, 2])), k[1, 2], k[1, 1]
    z_eye = m.anchors["seam/handles"][0, 2] + 0.1
    row = [int(cy + f * (z_eye - z) / 0.8) for z in (m.anchors["seam/handles"][0, 2] - 0.05,
                                                     m.anchors["seam/band"][0, 2] + 0.1)]
    rows = slice(row[0], min(row[1], 359))                        # below the handle, above the sill: door skin only
    assert rows.stop - rows.start > 40
    assert (seamed.labels.class_id[rows, cx - 40:cx + 40] == class_table().id("car")).all()
    lum_s, lum_p = seamed.rgb[rows].mean(-1), plain.rgb[rows].mean(-1)
    # the seam: image column cx (its world x is the camera's), a few pixels wide at 0.8 m
    col_s = lum_s[:, cx - 2:cx + 3].min(1).mean()
    col_p = lum_p[:, cx - 2:cx + 3].min(1).mean()
    assert col_s < 0.5 * col_p                                   # a dark groove where the doors meet
    away = np.r_[cx - 40:cx - 10, cx + 10:cx + 40]
    np.testing.assert_allclose(lum_s[:, away].mean(), lum_p[:, away].mean(), rtol=0.03)   # the door skin as before
    assert (seamed.labels.class_id == plain.labels.class_id).all()   # labels: the same pixels, seams or not


@pytest.fixture(scope="module")
def front_views(tmp_path_factory, test_spec):
    """The sedan's nose square on from 0.9 m, the camera 1 cm above its front bumper's edge; 320 x 180."""
    from generator.geometry import pose

    def place(m, y):   # yaw 180 degrees: the nose faces the camera at the origin looking along +x
        return pose(0.9 + m.bounds()[1][0], y, 0.0, yaw=np.pi)

    m = car(np.random.default_rng(2), variant="sedan")
    z = float(m.anchors["seam/bumpers"][0, 2]) + 0.01             # the bumper's edge crosses the grille
    frames, k, m = _seamed_and_plain(tmp_path_factory, test_spec, place, z, (320, 180), 160.0)
    return frames, k, m, 0.9, z


@pytest.mark.blender
def test_the_grille_has_slats_and_the_plain_trim_does_not(front_views):
    (seamed, plain), *_ = front_views
    crop = (slice(80, 100), slice(150, 170))                      # the middle of the grille, 0.9 m ahead
    assert (seamed.labels.class_id[crop] == class_table().id("car")).all()
    rows_s, rows_p = seamed.rgb[crop].mean((1, 2)), plain.rgb[crop].mean((1, 2))
    # slats catch the light between dark gaps: rows alternate; the plain black box is even
    assert rows_s.min() < 0.6 * rows_p.min()                      # the gaps between slats: darker than plain trim
    assert rows_s.std() > 2.5 * rows_p.std()                       # light and dark rows, not noise about one level


@pytest.mark.blender
def test_a_headlamp_shows_dark_projector_lenses_where_the_plain_lens_is_even(front_views):
    (seamed, plain), k, m, gap, z_eye = front_views
    x, y, z = m.anchors["headlight"][0]                         # the lamp on the car's +y side: image right
    depth = gap + m.bounds()[1][0] - x
    v = int(round(k[1, 2] - k[1, 1] * (z - z_eye) / depth))
    lum_s, lum_p = seamed.rgb.mean(-1), plain.rgb.mean(-1)
    for du in (-0.035, 0.035):                                   # the two projectors either side of the centre
        u = int(round(k[0, 2] + k[0, 0] * (abs(y) + du) / depth))
        eye = (slice(v - 1, v + 2), slice(u - 1, u + 2))
        assert (seamed.labels.class_id[eye] == class_table().id("car")).all()
        assert lum_s[eye].mean() < 0.6 * lum_p[eye].mean()     # dark glass, not the plain lens's grey
