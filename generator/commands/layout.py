"""``urbangen layout SPEC --out DIR``: build the town and write its map, GLB and summary.

Writes ``<name>_map.png`` (top-down class map with route 0, legend and scale bar),
``<name>.glb`` (the scene for any 3D viewer) and ``<name>_summary.json`` (objects and
triangles per class, totals, bounds, seed, spec hash, route lengths, build time). Nothing
is written until the scene is built and every file is ready; each file is written atomically.
"""

from __future__ import annotations

import argparse
import io
import logging
import os
import time

from generator import __version__
from generator.atomic import inside, staging, write_bytes, write_json
from generator.commands.options import Number, path, text_path
from generator.commands.preflight import output_dir
from generator.spec import load_spec

log = logging.getLogger("urbangen.layout")


def register(subparsers) -> None:
    p = subparsers.add_parser("layout", help="build the procedural town; write a map PNG, a GLB and a summary",
                              description=__doc__.splitlines()[0])
    p.add_argument("spec", type=text_path, help="scene spec JSON (e.g. scenes/default_town.json)")
    p.add_argument("--out", required=True, type=path, help="output folder (created if missing)")
    p.add_argument("--ppm", type=Number(0.5, 20), default=None,
                   help="map pixels per metre, in [0.5, 20] (default: 8, less for big towns)")
    p.set_defaults(func=run)


def summary(scene, spec, build_s: float) -> dict:
    """The JSON summary of a built scene."""
    from generator.layout.assemble import class_counts

    counts = class_counts(scene)
    info = {
        "name": spec.name,
        "urbangen": __version__,
        "seed": spec.seed,
        "spec_hash": spec.spec_hash,
        "digest": scene.digest(),
        "bounds_m": [[round(float(v), 3) for v in row] for row in scene.bounds],
        "totals": {"objects": len(scene.objects), "things": sum(o.instance_id > 0 for o in scene.objects),
                   "triangles": int(len(scene.faces)), "vertices": int(len(scene.vertices)),
                   "prototypes": len(scene.prototypes), "proxies": len(scene.proxies),
                   "proxy_triangles": int(len(scene.proxy_arrays["faces"]))},
        "classes": counts,
        "kinds": _kinds(scene),
        "routes": [{"name": p.name, "length_m": round(p.length(), 2), "samples": int(len(p.points)),
                    "closed": p.closed} for p in scene.paths],
        "build_seconds": round(build_s, 3),
    }
    from generator.layout.closures import closed_record
    from generator.layout.roundabouts import roundabout_record
    from generator.layout.streets import make_grid

    grid = make_grid(spec)
    ring, closed = roundabout_record(grid), closed_record(grid)
    if ring is not None:     # only towns with roundabouts or closed streets: the others' summaries read as before
        info["roundabouts"] = ring
    if closed is not None:
        info["closed_streets"] = closed
    return info


def _kinds(scene) -> dict[str, int]:
    out: dict[str, int] = {}
    for o in scene.objects:
        out[o.kind] = out.get(o.kind, 0) + 1
    return dict(sorted(out.items()))


def run(args: argparse.Namespace) -> int:
    from generator.formats.glb import scene_to_glb
    from generator.previews.layout_map import render_map
    from generator.layout.assemble import build_scene

    spec = load_spec(args.spec)
    out = output_dir(args.out, "--out")
    files = {k: out / f"{spec.name}{suffix}" for k, suffix in
             (("map", "_map.png"), ("glb", ".glb"), ("summary", "_summary.json"))}
    t0 = time.perf_counter()
    log.info("building %s from %s", spec.name, args.spec)
    scene = build_scene(spec)
    build_s = time.perf_counter() - t0
    log.info("rendering the map")
    img = render_map(scene, ppm=args.ppm, marker_spacing_m=spec.paths.spacing_m, title=spec.name)
    png = io.BytesIO()
    img.save(png, format="PNG", optimize=False)
    log.info("exporting GLB")
    glb = scene_to_glb(scene)
    info = summary(scene, spec, build_s)
    with staging(out, "layout") as stage:  # all three written in full before any is moved into place
        staged = {k: inside(stage, p.name) for k, p in files.items()}
        write_bytes(staged["map"], png.getvalue())
        write_bytes(staged["glb"], glb)
        write_json(staged["summary"], info)
        for k, p in staged.items():
            os.replace(p, files[k])
    t = info["totals"]
    log.info("wrote %s: %d objects, %d triangles, routes %s m", out, t["objects"], t["triangles"],
             ", ".join(f"{r['length_m']:.0f}" for r in info["routes"]))
    for written in files.values():
        print(written)
    return 0
