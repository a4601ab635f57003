"""``urbangen layout SPEC --out DIR``: build the town and write its map, GLB and summary.

Writes ``<name>_map.png`` (top-down class map with route 0, legend and scale bar),
``<name>.glb`` (the scene for any 3D viewer) and ``<name>_summary.json`` (objects and
triangles per class, totals, bounds, seed, spec hash, route lengths, build time). Nothing
is written until the scene is built and every file is ready; each file is written atomically.

A spec with ``town.redraw_every_frames`` shows a new town every N frames, none of them drawn from
the spec's own seed; ``--town I`` builds town ``I`` (as ``generate`` draws it, files named
``<name>_town<I>_*``), and without it the command refuses the spec (one line, exit 2) rather
than show a town no dataset of the spec contains. ``lidar`` takes the same option.
"""

from __future__ import annotations

import argparse
import io
import logging
import os
import time

from generator import __version__
from generator.atomic import inside, staging, write_bytes, write_json
from generator.commands.options import Integer, Number, path, text_path
from generator.commands.preflight import output_dir
from generator.errors import UserError
from generator.spec import load_spec

log = logging.getLogger("urbangen.layout")


def register(subparsers) -> None:
    p = subparsers.add_parser("layout", help="build the procedural town; write a map PNG, a GLB and a summary",
                              description=__doc__.splitlines()[0])
    p.add_argument("spec", type=text_path, help="scene spec JSON (e.g. scenes/default_town.json)")
    p.add_argument("--out", required=True, type=path, help="output folder (created if missing)")
    p.add_argument("--ppm", type=Number(0.5, 20), default=None,
                   help="map pixels per metre, in [0.5, 20] (default: 8, less for big towns)")
    add_town_argument(p)
    p.set_defaults(func=run)


MAX_TOWN = 100_000   #: as town.redraw_every_frames: no run has more towns than frames


def add_town_argument(p) -> None:
    """``--town I``: town ``I`` of a spec with ``town.redraw_every_frames`` (``layout`` and ``lidar``)."""
    p.add_argument("--town", type=Integer(0, MAX_TOWN), default=None,
                   help="with a spec that sets town.redraw_every_frames (a new town every N frames): build "
                        "town I, drawn as generate draws it (its own seed); required for such a spec")


def spec_for_town(spec, town: int | None):
    """The spec of the town ``--town`` names (``spec`` itself for a spec that re-draws no town).

    Raises
    ------
    UserError
        One line when a re-drawing spec comes without ``--town`` or ``--town`` comes with a spec
        that re-draws no town (either would build a town the user did not ask for).
    """
    from generator.spec.towns import redraw_every, town_spec

    n = redraw_every(spec)
    if n is None:
        if town is not None:
            raise UserError(f"--town: {spec.source} re-draws no town (town.redraw_every_frames is null); "
                            "leave --town out")
        return spec
    if town is None:
        raise UserError(f"{spec.source}: town.redraw_every_frames = {n} draws a new town every {n} frames, none "
                        "from the spec's own seed: pass --town I for town I (frames I*N..) as generate draws it")
    return town_spec(spec, town)


def summary(scene, spec, build_s: float) -> dict:
    """The JSON summary of a built scene."""
    from generator.layout.assemble import class_counts
    from generator.spec.towns import town_record

    counts = class_counts(scene)
    info = {
        "name": spec.name,
        "urbangen": __version__,
        "seed": spec.seed,
        **({"town": town_record(spec)} if spec.town_index is not None else {}),
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
        **_streets(spec, scene.grid),
    }
    if scene.town_map is not None:   # streets crossing at an angle (the towns with right angles read as before)
        info["intersection_angle"] = {
            "angle_deg": round(scene.town_map.angle_deg, 4),
            "lean": scene.town_map.lean,
            "grid_to_world_xy": [[round(float(v), 9) for v in row] for row in scene.town_map.A],
        }
    from generator.layout.network.closures import closed_record
    from generator.layout.network.roundabouts import roundabout_record

    ring, closed = roundabout_record(scene.grid), closed_record(scene.grid)    # the grid the town was built on
    if ring is not None:     # only towns with roundabouts or closed streets: the others' summaries read as before
        info["roundabouts"] = ring
    if closed is not None:
        info["closed_streets"] = closed
    return info


def _streets(spec, grid) -> dict:
    """``{"streets": [...]}``: each segment's drawn cross-section of ``grid``, when the spec has ``streets``."""
    from generator.layout.network.cross_sections import sections_record

    rows = sections_record(grid) if spec.streets is not None else []
    return {"streets": rows} if rows else {}


def _kinds(scene) -> dict[str, int]:
    out: dict[str, int] = {}
    for o in scene.objects:
        out[o.kind] = out.get(o.kind, 0) + 1
    return dict(sorted(out.items()))


def run(args: argparse.Namespace) -> int:
    from generator.formats.glb import scene_to_glb
    from generator.layout.assemble import build_scene
    from generator.previews.layout_map import render_map

    spec = spec_for_town(load_spec(args.spec), args.town)
    out = output_dir(args.out, "--out")
    stem = spec.name if spec.town_index is None else f"{spec.name}_town{spec.town_index}"
    files = {k: out / f"{stem}{suffix}" for k, suffix in
             (("map", "_map.png"), ("glb", ".glb"), ("summary", "_summary.json"))}
    t0 = time.perf_counter()
    log.info("building %s from %s", spec.name, args.spec)
    scene = build_scene(spec)
    build_s = time.perf_counter() - t0
    log.info("rendering the map")
    img = render_map(scene, ppm=args.ppm, marker_spacing_m=spec.paths.spacing_m, title=stem)
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
