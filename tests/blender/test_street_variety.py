"""What the camera sees of one-way and shared streets (Cycles, tiny renders).

A user relies on: the "no entry" sign a driver at a one-way street's exit node sees is red, the
"one way" sign at its entry is blue (the traffic_sign pixels of those views), and a shared street's
carriageway does not look like the pavement beside it (its road pixels are warmer than the
sidewalk pixels of the same frame; before, both were the same concrete slabs).
"""

from __future__ import annotations

import dataclasses
import os

import numpy as np
import pytest

from generator.labels import class_table
from generator.layout import build_scene
from generator.layout.network.cross_sections import shared_segments
from generator.layout.network.draw import make_grid
from generator.layout.placement.one_way_signs import one_way_ends
from generator.spec import parse_spec
from generator.world import rig

pytestmark = pytest.mark.blender


@pytest.fixture(scope="module")
def views(tmp_path_factory):
    """(grid, {view: RenderedFrame}) of a 3 x 3 town with one-way and shared streets."""
    from generator.blender.renderer import Renderer
    from generator.spec.render import load_render_config
    from generator.weather import Lighting

    spec = parse_spec({"name": "street_variety", "seed": 4,
                       "town": {"blocks_x": 3, "blocks_y": 3, "block_size_m": 50, "block_size_jitter_m": 6,
                                "margin_m": 20},
                       "density": {"moving_cars_per_100m": 0, "trees_per_100m": 0, "people_per_100m": 0},
                       "streets": {"types": {"plain": 1, "one_way": 2, "shared": 1}}}, "street_variety.json")
    grid = make_grid(spec)
    scene = build_scene(spec)
    cfg = dataclasses.replace(load_render_config("test"), resolution=(320, 180), samples=4)
    r = Renderer(scene, spec, cfg, tmp_path_factory.mktemp("views"))
    r.set_conditions(Lighting("day", sun_elevation_deg=70.0, sun_azimuth_deg=215.0))
    seg, d, entry, exit_ = one_way_ends(grid)[0]
    flow = seg.yaw if d > 0 else seg.yaw + np.pi
    f = np.array([np.cos(flow), np.sin(flow)])
    sh = shared_segments(grid)[0]
    u = np.array([np.cos(sh.yaw), np.sin(sh.yaw)])
    poses = {"entry": (grid.node_xy(entry) - 4.0 * f, flow, 4.0),
             "exit": (grid.node_xy(exit_) + 4.0 * f, flow + np.pi, 4.0),
             "shared": (grid.node_xy(sh.a) + (grid.road_half + 4.0) * u, sh.yaw, 20.0)}
    out = {}
    debug = os.environ.get("UG_VIEWS_PNG")     # a folder: write each view (RGB | class) there to look at
    for name, (xy, heading, pitch_deg) in poses.items():
        T = rig.camera_extrinsics((float(xy[0]), float(xy[1]), 1.6), (0.0, 0.0, 0.0),
                                  (heading, np.radians(pitch_deg), 0.0))
        out[name] = r.render(T, seed=0, light_info={})
        if debug:
            from PIL import Image

            from generator.previews.preview import colorize, display_rgb

            Image.fromarray(np.concatenate([display_rgb(out[name].rgb), colorize(out[name].labels.class_id)], 1)) \
                .save(os.path.join(debug, f"{name}.png"))
    return grid, out


def _mean_rgb(frame, cls: str, rows=slice(None)) -> np.ndarray:
    mask = frame.labels.class_id[rows] == class_table().id(cls)
    assert mask.sum() >= 20, f"too few {cls} pixels to judge"
    return frame.rgb[rows][mask].mean(0)


def test_the_no_entry_sign_reads_red_and_the_one_way_sign_blue(views):
    _, out = views
    exit_rgb = _mean_rgb(out["exit"], "traffic_sign")
    entry_rgb = _mean_rgb(out["entry"], "traffic_sign")
    assert exit_rgb[0] > 1.5 * exit_rgb[2], f"no-entry sign pixels are not red: {exit_rgb}"
    assert entry_rgb[2] > 1.5 * entry_rgb[0], f"one-way sign pixels are not blue: {entry_rgb}"


def test_shared_paving_looks_unlike_the_sidewalk_beside_it(views):
    _, out = views
    frame = out["shared"]
    h = frame.rgb.shape[0]
    road = _mean_rgb(frame, "road", slice(h // 2, None))       # the near half: the shared carriageway
    walk = _mean_rgb(frame, "sidewalk")
    warm = lambda c: float((c[0] - c[2]) / c.sum())             # noqa: E731
    assert warm(road) > warm(walk) + 0.08, (road, walk)
