"""Ground surfaces and the edge of the world (issue 29 items 2 and 6) as the camera sees them: the
gutter by the kerb, the far city closing the view out of town and its lit windows at night."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from generator.labels import class_table
from generator.weather import Lighting
from kits.camera_kit import look_at

pytestmark = pytest.mark.blender

ROAD, PARKING, CURB = (class_table().id(n) for n in ("road", "parking", "curb"))
BUILDING, VEGETATION, SKY = (class_table().id(n) for n in ("building", "vegetation", "sky"))
DAY = Lighting("day", sun_elevation_deg=88.0, sun_azimuth_deg=150.0)    # overhead: no shadow over the gutter




def _clear_kerb(scene, grid):
    """(segment transform, u) of the stretch of kerb farthest from every thing and lamp (a top-down view)."""
    things = np.array([o.box.center[:2] for o in scene.objects if o.instance_id > 0 or o.kind == "lamp_post"])
    best = (0.0, None, None)
    for o in scene.objects:
        if o.kind != "street":
            continue
        T, length = o.transform, float(max(o.box.size[:2]))
        for u in np.linspace(0.2, 0.8, 25) * length:
            p = (T[:3, :3] @ [u, -grid.road_half, 0.0] + T[:3, 3])[:2]
            best = max(best, (float(np.linalg.norm(things - p, axis=1).min()), T, u), key=lambda b: b[0])
    assert best[0] > 4.0, "no clear kerb in the test town"
    return best[1], best[2]


@pytest.fixture(scope="module")
def ground(test_spec, test_scene, tmp_path_factory):
    from generator.blender.renderer import Renderer
    from generator.spec.render import load_render_config

    cfg = dataclasses.replace(load_render_config("test"), resolution=(96, 96), samples=4)
    r = Renderer(test_scene, test_spec, cfg, tmp_path_factory.mktemp("ground"))
    grid = test_scene.grid
    T, u = _clear_kerb(test_scene, grid)
    centre = T[:3, :3] @ [u, -(grid.road_half - 1.5), 0.0] + T[:3, 3]
    # straight down from 5 m over the carriageway 1.5 m off the kerb; image x runs across the street
    r.place_camera(look_at(centre + [0, 0, 5.0], centre + T[:3, :3] @ [0.0001, 0.0, -1.0]))
    out = {"labels": r.render_labels()}
    for name, wet in (("dry", 0.0), ("wet", 1.0)):
        r.set_conditions(DAY, wet, 11.0)
        out[name] = r.render_rgb(seed=3)[0]
    # out of town at the far city: 8 m up, 15 m outside the town's south-west corner, looking out level
    (bx0, by0), _ = test_scene.bounds
    eye = np.array([bx0 - 15.0, by0 - 15.0, 8.0])
    r.place_camera(look_at(eye, eye + [-100.0, -100.0, 0.0]))
    out["far_labels"] = r.render_labels()
    r.set_conditions(Lighting("night", lit_windows=1.0))
    out["night_lit"] = r.render_rgb(seed=3)[0]
    r.set_conditions(Lighting("night", lit_windows=0.0))
    out["night_dark"] = r.render_rgb(seed=3)[0]
    out["tagged"] = {ob.name: ob.get("ug_kerb_v") for ob in r.handles.objects}
    return out


def test_street_objects_know_their_kerb(test_scene, ground):
    """The gutter needs the kerb's offset: every street segment carries it, nothing else does."""
    tagged = ground["tagged"]
    streets = [o.name for o in test_scene.objects if o.kind == "street"]
    assert streets and all(tagged[n] == pytest.approx(test_scene.grid.road_half) for n in streets)
    assert all(v is None for n, v in tagged.items() if n not in streets)


def _bands(ground):
    """Carriageway pixels of the top-down view by distance to the kerb: (gutter, open road) masks."""
    cls = ground["labels"].real_class
    carriage = np.isin(cls, (ROAD, PARKING))
    kerb_cols = np.nonzero((cls == CURB).any(0))[0]
    assert carriage.sum() > 2000 and len(kerb_cols), "the view shows the carriageway and the kerb"
    cols = np.arange(cls.shape[1])
    # the kerb is on the image's left or right: distance (pixels, ~19 px per metre) from its nearest column
    d = np.abs(cols[None, :] - (kerb_cols.min() if kerb_cols.min() > 0 else kerb_cols.max()))
    d = np.broadcast_to(d, cls.shape)
    return carriage & (d <= 8), carriage & (d >= 20)


def test_gutter_by_the_kerb_is_dusty(ground):
    gutter, road = _bands(ground)
    lum = ground["dry"].mean(-1)
    assert gutter.sum() > 200 and road.sum() > 1000
    assert lum[gutter].mean() > 1.1 * lum[road].mean(), (lum[gutter].mean(), lum[road].mean())


def test_far_city_fills_the_view_out_of_town_and_lights_its_windows(ground):
    """Looking level out of town from 8 m up, the row just above the horizon (0.6 degrees; the bare
    ground's edge, 2 km away, lies 0.2 degrees below it) shows buildings and trees, not sky; at night
    the far city's windows light up."""
    cls = ground["far_labels"].real_class
    band = cls[cls.shape[0] // 2 - 1]
    assert (band == SKY).mean() < 0.1, "sky meets the ground"
    assert np.isin(band, (BUILDING, VEGETATION)).mean() > 0.9
    far = (ground["far_labels"].depth > 150.0) & (cls == BUILDING)
    assert far.sum() > 30, int(far.sum())
    lit, dark = ground["night_lit"].mean(-1), ground["night_dark"].mean(-1)
    assert lit[far].mean() > 3 * dark[far].mean(), (lit[far].mean(), dark[far].mean())
