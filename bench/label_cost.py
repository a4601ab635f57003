"""What the label passes add to a frame, in the worker's order, beside the per-frame switching they replaced.

One process, one town with its traffic, the same frames rendered three ways (issue 14 item 6):

* ``rgb only``: expose, conditions, RGB pass -- the frame without labels;
* ``before``: per frame, the label state as it was (material *and* world override, written on
  every switch even when unchanged), real and label passes, then the RGB pass after writing
  both overrides back to None -- Cycles recompiled every shader and redid the sky on each switch;
* ``batched``: :func:`generator.jobs.variants.render_frames`' order -- the label passes of a
  batch of frames behind one switch (the world stays, sky from the Z pass), then the RGB passes.

The label cost of a mode is its frame time minus the ``rgb only`` frame time, per frame, as a
share of the ``rgb only`` frame. Wall and CPU seconds are both printed: on a machine shared with
other work, CPU seconds (both Cycles threads) are the steadier figure.

    python bench/label_cost.py [--config preview] [--frames 8] [--rounds 1]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path


def _legacy_label_world():
    """The label world the ``before`` mode overrides the world with (emits the sky class)."""
    from generator.blender.bpy_guard import bpy
    from generator.blender.nodes import Nodes
    from generator.labels import class_table

    world = bpy.data.worlds.get("bench_label_world")
    if world is None:
        world = bpy.data.worlds.new("bench_label_world")
        g = Nodes(world.node_tree)
        bg = g.node("ShaderNodeBackground")
        g.set(bg.inputs["Color"], (float(class_table().id("sky")), 0.0, 0.0))
        g.output(bg.outputs[0], "ShaderNodeOutputWorld")
        world.cycles.sampling_method = "NONE"
    return world


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--spec", default="scenes/default_town.json")
    ap.add_argument("--config", default="preview")
    ap.add_argument("--frames", type=int, default=8)
    ap.add_argument("--rounds", type=int, default=1)
    a = ap.parse_args()

    from generator.blender.materials import label_material
    from generator.blender.renderer import Renderer
    from generator.jobs.drive import MARGIN_M
    from generator.jobs.variants import label_batch_size, pose_for
    from generator.layout import build_scene
    from generator.spec import load_spec
    from generator.spec.render import load_render_config
    from generator.traffic.build import build_world
    from generator.weather import draw_lighting, frame_wetness
    from generator.world.rig import Rig

    spec, cfg = load_spec(a.spec), load_render_config(a.config)
    scene = build_scene(spec)
    world = build_world(spec, scene, 0.0, (a.frames + 1) * spec.paths.spacing_m + MARGIN_M)
    rig = Rig.from_world(spec, world)
    r = Renderer(scene, spec, cfg, Path(tempfile.mkdtemp(prefix="ug_labelcost_")), world)
    vl = r.bscene.view_layers[0]
    frames = [rig.frame(i) for i in range(1, a.frames + 1)]

    def rgb(f, legacy: bool) -> None:
        pose_for(r, f, rig)()
        r.set_conditions(draw_lighting(spec, f.index, "day"), *frame_wetness(spec, f.index))
        if legacy:
            vl.material_override = None
            vl.world_override = None
        r.render_rgb(seed=f.index)

    def rgb_only():
        for f in frames:
            rgb(f, False)

    inside = {"before": 0.0, "batched": 0.0}

    def before():
        # the passes now switch every material's own label branch (generator.blender.materials); the
        # old way set the label material as the view layer's override, so ``before`` asks for it
        from generator.blender import session

        own = session.label_state
        session.label_state = lambda scene, material=None: own(scene, label_material())
        try:
            for f in frames:
                t = time.perf_counter()
                pose_for(r, f, rig)()
                vl.material_override = label_material()
                vl.world_override = _legacy_label_world()
                r.render_labels()
                inside["before"] += time.perf_counter() - t
                rgb(f, True)
        finally:
            session.label_state = own

    def batched():
        n = label_batch_size(cfg)
        for i in range(0, len(frames), n):
            batch = frames[i:i + n]
            t = time.perf_counter()
            r.render_labels_batch([pose_for(r, f, rig) for f in batch])
            inside["batched"] += time.perf_counter() - t
            for f in batch:
                rgb(f, False)

    rgb(frames[0], False)  # warm-up: BVH, shaders, sky
    modes = {"rgb only": rgb_only, "before": before, "batched": batched}
    wall = {m: 0.0 for m in modes}
    cpu = dict(wall)
    for k in range(a.rounds):
        for name in list(modes)[:: 1 if k % 2 == 0 else -1]:   # alternate the order: no mode always first
            run = modes[name]
            t, c = time.perf_counter(), time.process_time()
            run()
            wall[name] += time.perf_counter() - t
            cpu[name] += time.process_time() - c
    n = a.frames * a.rounds
    print(f"{cfg.name} {cfg.width}x{cfg.height}, {cfg.samples} spp, label_supersample {cfg.label_supersample}, "
          f"{a.frames} frames x {a.rounds} rounds, label batch {label_batch_size(cfg)} frames")
    print(f"{'mode':<10}{'wall s/frame':>14}{'labels add':>12}{'share':>8}"
          f"{'cpu s/frame':>14}{'labels add':>12}{'share':>8}"
          f"{'in label calls':>16}{'share':>8}")
    base_w, base_c = wall["rgb only"] / n, cpu["rgb only"] / n
    for name in modes:
        w, c = wall[name] / n, cpu[name] / n
        li = inside.get(name, 0.0) / n
        print(f"{name:<10}{w:>14.2f}{w - base_w:>12.2f}{(w - base_w) / base_w:>8.1%}"
              f"{c:>14.2f}{c - base_c:>12.2f}{(c - base_c) / base_c:>8.1%}{li:>16.2f}{li / base_w:>8.1%}")
    print("share = (frame time - rgb only frame time) / rgb only frame time; "
          "'in label calls': wall seconds inside the\n"
          "label-pass calls (posing, state switch, renders, vote), whatever the RGB renders pay afterwards. "
          "Target <= 10 %.")


if __name__ == "__main__":
    main()
