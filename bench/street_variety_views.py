"""Render what a driver sees at one-way and shared streets: RGB beside the class labels.

A 3 x 3 town with one-way, shared and plain streets (seed ``--seed``); shots at driver's eye height
(1.6 m, 8 degrees down):

* ``entry``: from the middle of the entry node of the first one-way street, looking along its flow
  (the "one way" signs on both sidewalks past the crosswalk);
* ``exit``: from the middle of its exit node, looking into it against the flow (the "no entry"
  signs a driver at that node would see);
* ``shared``: 4 m into the first shared street past its start node's crosswalk, looking along it
  (its block paving beside the sidewalks' concrete slabs).

Each shot is one row of the PNG: RGB | class colours. Render time per shot is printed.

Usage::

    python bench/street_variety_views.py OUT.png [--seed 4] [--size 480x270] [--samples 16]
"""

from __future__ import annotations

import argparse
import dataclasses
import tempfile
import time
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from generator.layout import build_scene
from generator.layout.network.cross_sections import shared_segments
from generator.layout.network.draw import make_grid
from generator.layout.placement.one_way_signs import one_way_ends
from generator.spec import parse_spec
from generator.world import rig

EYE_M, PITCH_DEG = 1.6, 8.0


def town_spec(seed: int):
    """A 3 x 3 town of 50 m blocks with one-way, shared and plain streets, no moving traffic."""
    return parse_spec({"name": "street_variety", "seed": seed,
                       "town": {"blocks_x": 3, "blocks_y": 3, "block_size_m": 50, "block_size_jitter_m": 6,
                                "margin_m": 20},
                       "density": {"moving_cars_per_100m": 0},
                       "streets": {"types": {"plain": 1, "one_way": 2, "shared": 1}}}, "street_variety.json")


def shots(grid) -> dict:
    """name -> (camera xyz (world, metres), heading (radians))."""
    out = {}
    ends = one_way_ends(grid)
    if ends:
        seg, d, entry, exit_ = ends[0]
        flow = seg.yaw if d > 0 else seg.yaw + np.pi
        f = np.array([np.cos(flow), np.sin(flow)])
        right = np.array([f[1], -f[0]])
        out["entry (one way)"] = (np.r_[grid.node_xy(entry) - 4.0 * f + 0.5 * grid.lane_w * right, EYE_M], flow)
        out["exit (no entry)"] = (np.r_[grid.node_xy(exit_) + 4.0 * f - 0.5 * grid.lane_w * right, EYE_M], flow + np.pi)
    shared = shared_segments(grid)
    if shared:
        seg = shared[0]
        u = np.array([np.cos(seg.yaw), np.sin(seg.yaw)])
        ahead = grid.road_half + 4.0          # just past the crosswalk, on the shared street itself
        out["shared street"] = (np.r_[grid.node_xy(seg.a) + ahead * u + 0.6 * np.array([u[1], -u[0]]), EYE_M], seg.yaw)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out", help="the views PNG to write")
    ap.add_argument("--seed", type=int, default=4)
    ap.add_argument("--size", default="480x270")
    ap.add_argument("--samples", type=int, default=16)
    a = ap.parse_args()

    from generator.blender.renderer import Renderer
    from generator.previews.preview import colorize, display_rgb
    from generator.spec.render import load_render_config
    from generator.weather import Lighting

    w, h = (int(v) for v in a.size.split("x"))
    spec = town_spec(a.seed)
    grid = make_grid(spec)
    t = time.perf_counter()
    scene = build_scene(spec)
    print(f"town built in {time.perf_counter() - t:.1f} s; one-way segments {len(one_way_ends(grid))}, "
          f"shared {len(shared_segments(grid))}")
    cfg = dataclasses.replace(load_render_config("test"), resolution=(w, h), samples=a.samples, max_bounces=4)
    r = Renderer(scene, spec, cfg, Path(tempfile.mkdtemp(prefix="ug_views_")))
    r.set_conditions(Lighting("day", sun_elevation_deg=40.0, sun_azimuth_deg=215.0))
    rows = []
    for name, (xyz, heading) in shots(grid).items():
        T = rig.camera_extrinsics(tuple(xyz), (0.0, 0.0, 0.0), (heading, np.radians(PITCH_DEG), 0.0))
        t = time.perf_counter()
        out = r.render(T, seed=0, light_info={})
        print(f"shot {name}: rendered in {time.perf_counter() - t:.1f} s ({w}x{h}, {a.samples} spp)")
        panels = [display_rgb(out.rgb), colorize(out.labels.class_id)]
        row = np.concatenate([np.pad(p, ((0, 4), (0, 4), (0, 0)), constant_values=255) for p in panels], 1)
        img = Image.fromarray(row)
        ImageDraw.Draw(img).text((6, 4), f"{name}: RGB | class", fill=(255, 255, 0))
        rows.append(np.asarray(img))
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(np.concatenate(rows, 0)).save(a.out)
    print(f"-> {a.out}")


if __name__ == "__main__":
    main()
