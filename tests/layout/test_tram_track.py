"""Where trams run, the line also leaves the street on a ballast bed: class ``rail_track`` appears.

The test town is built for it: two blocks, parks on every open lot, one tram (on the middle
street, the one lane no route drives). Its reserved track must lie along an open lot lining the
tram's street, reach the LiDAR labels (SemanticKITTI other-ground 49) and the image masks, and map
to a class in every label set. A town without trams is unchanged (the step draws nothing).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from generator.labels import class_table
from generator.labels.sets import label_sets, semantickitti_labels
from generator.layout import build_scene
from generator.layout.lots.lot import make_lots
from generator.layout.network.draw import make_grid
from generator.lidar.scan import Scanner
from generator.lidar.sensors import sensor_for_spec
from generator.spec import parse_spec
from generator.world.rig import Rig

RAIL = class_table().id("rail_track")
TRAM_TOWN = {"name": "tram_town", "seed": 5,
             "town": {"blocks_x": 2, "blocks_y": 1, "block_size_m": 50, "block_size_jitter_m": 0, "margin_m": 12},
             "density": {"trams": 1, "buildings": 0.4, "parks": 1.0, "trees_per_100m": 2, "parked_cars_per_100m": 4},
             "paths": {"spacing_m": 6}}


@pytest.fixture(scope="module")
def tram_town():
    spec = parse_spec(TRAM_TOWN, "tram_town.json")
    return spec, build_scene(spec)


def _track(scene):
    return [o for o in scene.objects if o.cls == "rail_track"]


def test_a_ballast_track_lines_the_tram_street(tram_town):
    spec, scene = tram_town
    trams, tracks = [o for o in scene.objects if o.kind == "tram"], _track(scene)
    assert len(trams) == spec.density.trams == 1 and len(tracks) == 1
    track, tram = tracks[0], trams[0]
    assert track.attrs["placement"] == "tram_track"
    lot = make_lots(spec, make_grid(spec))[track.attrs["lot"]]
    assert lot.use in ("park", "yard")                          # open ground, not a built lot
    yaw = lambda T: np.arctan2(T[1, 0], T[0, 0])               # noqa: E731
    assert abs(np.sin(yaw(track.transform) - yaw(tram.transform))) < 1e-6   # parallel to the tram's street
    grid = make_grid(spec)
    d = np.array([np.cos(yaw(tram.transform)), np.sin(yaw(tram.transform))])
    off = track.transform[:2, 3] - tram.transform[:2, 3]
    assert abs(off[0] * d[1] - off[1] * d[0]) < grid.corridor_half + 8.0   # beside that street, not across town
    faces = scene.face_class == RAIL
    assert faces.sum() > 100
    z = scene.vertices[scene.faces[faces]][..., 2]
    assert z.min() == pytest.approx(grid.curb_h,
                                    abs=1e-6) and 0.4 < z.max() - grid.curb_h < 0.8   # bed + rails on the lot


def test_town_without_trams_gets_no_track(test_spec):
    assert test_spec.density.trams == 0
    assert not (build_scene(test_spec).face_class == RAIL).any()


def test_rail_track_maps_in_every_label_set():
    t = class_table()
    sets = label_sets()
    assert sets["native"].names[sets["native"].from_native[RAIL]] == "rail_track"
    assert int(t.to_semantickitti[RAIL]) == 49
    assert sets["semantickitti"].names[sets["semantickitti"].from_native[RAIL]] == "other-ground"
    assert sets["unified11"].names[sets["unified11"].from_native[RAIL]] == "other-ground"
    assert int(t.to_cityscapes[RAIL]) == 10           # Cityscapes "rail track"


def test_lidar_labels_the_track(tram_town):
    """Sweeps along the route hit the bed; their points carry rail_track, written as raw 49."""
    spec, scene = tram_town
    rig = Rig.from_spec(spec, scene)
    hits = 0
    with Scanner(scene, sensor_for_spec(spec), threads=2) as sc:
        for k in np.linspace(0, rig.max_frames() - 1, 12).round().astype(int):
            pts = sc.sweep(rig, rig.frame(int(k)).t, spec.sensors.lidar.motion_skew).points
            on = pts["class"] == RAIL
            hits += int(on.sum())
            if on.any():
                assert set(np.unique(semantickitti_labels(pts["class"][on], pts["moving"][on]))) == {49}
    assert hits > 50


@pytest.mark.blender
def test_mask_shows_the_track(tram_town, tmp_path):
    from generator.blender.renderer import Renderer
    from generator.spec.render import load_render_config
    from generator.weather import Lighting
    from generator.world import rig

    spec, scene = tram_town
    track = _track(scene)[0]
    T = track.transform
    centre = T[:3, 3] + np.array([0.0, 0.0, 0.3])
    across = T[:3, 1]                                   # the lot's b axis: from the street into the lot
    eye = centre - 9.0 * across + np.array([0.0, 0.0, 2.5])
    look = centre - eye
    yaw = np.degrees(np.arctan2(look[1], look[0]))
    pitch = np.degrees(np.arctan2(-look[2], np.hypot(look[0], look[1])))
    cfg = dataclasses.replace(load_render_config("test"), resolution=(160, 90), samples=1)
    r = Renderer(scene, spec, cfg, tmp_path)
    r.set_conditions(Lighting("day", sun_elevation_deg=45.0, sun_azimuth_deg=200.0))
    out = r.render(rig.camera_extrinsics(tuple(eye), (0.0, pitch, yaw)), seed=0, light_info={})
    rail = out.labels.class_id == RAIL
    assert rail.sum() > 0.02 * rail.size                # the bed fills a visible part of the view
    assert (out.labels.real_class[rail] == RAIL).all()  # no hull: the mask is the track's own faces
