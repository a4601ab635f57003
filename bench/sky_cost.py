"""Bench of the sky's render cost (issue 14 item 2): Cycles seconds of one RGB pass under a cloudless
sky (the world of before: Blender's sky texture only), broken clouds, an overcast deck and a night,
side by side in one process, alternating so machine load hits every case alike.

    python bench/sky_cost.py [SPEC] [--config preview] [--frame 3] [--repeat 3] [--width 320]

Prints the median seconds per case and its ratio to the cloudless sky.
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics
import tempfile
import time

from generator.layout import build_scene
from generator.spec.load import load_spec
from generator.spec.render import load_render_config
from generator.weather import draw_lighting
from generator.world.rig import Rig


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("spec", nargs="?", default="scenes/default_town.json")
    p.add_argument("--config", default="preview")
    p.add_argument("--frame", type=int, default=3)
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--width", type=int, default=320)
    a = p.parse_args(argv)
    from generator.blender.renderer import Renderer  # imports bpy

    spec = load_spec(a.spec)
    cfg = load_render_config(a.config)
    cfg = dataclasses.replace(cfg, resolution=(a.width, round(a.width * cfg.height / cfg.width)))
    scene = build_scene(spec)
    frame = Rig.from_spec(spec, scene).frame(a.frame)  # the static town (no traffic): the sky is what changes
    r = Renderer(scene, spec, cfg, tempfile.mkdtemp(prefix="sky_cost_"))
    r.place_camera(frame.T_world_camera)
    day = draw_lighting(spec, a.frame, "day", "clear")
    cases = {
        "cloudless sky (before)": dataclasses.replace(day, cloud_cover=0.0),
        "broken clouds (cover 0.5)": dataclasses.replace(day, cloud_cover=0.5),
        "overcast deck": draw_lighting(spec, a.frame, "day", "rain"),
        "night": draw_lighting(spec, a.frame, "night", "clear"),
    }
    times = {k: [] for k in cases}
    for i in range(a.repeat):
        for name, light in cases.items():
            r.set_conditions(light)
            t = time.perf_counter()
            r.render_rgb(seed=i)
            times[name].append(time.perf_counter() - t)
    base = statistics.median(times["cloudless sky (before)"])
    print(f"{a.spec} frame {a.frame}, {a.config} at {cfg.width}x{cfg.height}, {a.repeat} repeats (median s)")
    for name, ts in times.items():
        m = statistics.median(ts)
        print(f"  {name:28s} {m:7.2f} s  x{m / base:5.2f}")


if __name__ == "__main__":
    main()
