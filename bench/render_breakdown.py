"""Per-frame time breakdown of the Blender render path (issue 3), printed as a table.

Stages: layout build, Blender scene build (once per process), then per frame the RGB
pass, the two label passes (real + proxies), EXR write, metadata and preview. The
label passes are shown as a share of the RGB pass measured in the same run (target
<= 10 %). Peak memory is the process's maximum RSS.

    python bench/render_breakdown.py [--spec scenes/default_town.json] [--config preview]
                                     [--frames 3] [--paper-frames 1]
"""

from __future__ import annotations

import argparse
import resource
import shutil
import tempfile
import time
from pathlib import Path


def run(spec_path: str, config: str, frames: int, first: int) -> dict:
    from generator.blender.renderer import Renderer
    from generator.jobs.images import write_image
    from generator.layout.assemble import build_scene
    from generator.spec import load_spec
    from generator.spec.render import load_render_config
    from generator.weather import draw_lighting
    from generator.world.rig import Rig

    spec, cfg = load_spec(spec_path), load_render_config(config)
    out = Path(tempfile.mkdtemp(prefix="ug_bench_"))
    t = time.perf_counter()
    scene = build_scene(spec)
    layout_s = time.perf_counter() - t
    r = Renderer(scene, spec, cfg, out / "scratch")
    rows = []
    for f in Rig.from_spec(spec, scene).frames(frames, first=first):
        info = r.set_conditions(draw_lighting(spec, f.index, "day"))
        rendered = r.render(f.T_world_camera, seed=f.index, light_info=info)
        _, secs = write_image(out, f, spec, cfg, r, rendered, "day", {"kind": "clear"})
        rows.append(secs)
    shutil.rmtree(out, ignore_errors=True)
    mean = {k: sum(s[k] for s in rows) / len(rows) for k in rows[0]}
    return {"config": cfg.name, "resolution": cfg.resolution, "samples": cfg.samples, "layout_s": layout_s,
            "blender_build_s": r.build_seconds, "frames": len(rows), **mean,
            "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--spec", default="scenes/default_town.json")
    ap.add_argument("--config", default="preview")
    ap.add_argument("--frames", type=int, default=3)
    ap.add_argument("--first", type=int, default=5)
    ap.add_argument("--paper-frames", type=int, default=1)
    a = ap.parse_args()
    results = [run(a.spec, a.config, a.frames, a.first)]
    if a.paper_frames:
        results.append(run(a.spec, "paper", a.paper_frames, a.first))
    cols = ["layout_s", "blender_build_s", "rgb_pass", "real_pass", "label_pass", "exr_write", "metadata", "preview"]
    print(f"{'preset':<9}{'res':>11}{'spp':>5}{'frames':>7}" + "".join(f"{c:>16}" for c in cols)
          + f"{'labels/RGB':>12}{'peak RSS MB':>13}")
    for res in results:
        share = (res["real_pass"] + res["label_pass"]) / res["rgb_pass"]
        print(f"{res['config']:<9}{'x'.join(map(str, res['resolution'])):>11}{res['samples']:>5}{res['frames']:>7}"
              + "".join(f"{res[c]:>16.3f}" for c in cols) + f"{share:>11.1%}{res['peak_rss_mb']:>13.0f}")
    print("per-frame stages are means over the frames; layout and Blender build happen once per process.")


if __name__ == "__main__":
    main()
