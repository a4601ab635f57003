"""``urbangen fuse DIR [--sequence NN] [--abs-tol M] [--rel-tol F] [--voxel M] [--no-deskew]``.

Projects every LiDAR scan of ``DIR/lidar/sequences/NN`` into its frame's image in
``DIR/images`` (seed 001 Eq. 1, de-skewed, with and without the occlusion test), compares
the mask class with each point's ray-cast class, and writes ``DIR/fusion/``:
``agreement.md``, ``agreement.json``, ``agreement.png`` (points over the labels coloured by
agreement, confusion matrices), and the semantic map of the sequence (seed 001 Eq. 2)
twice: ``semantic_map_lidar.{ply,png}`` (every point, its ray-cast class) and
``semantic_map_camera.{ply,png}`` (points the camera sees, labelled from the masks).
With --image-labels PRED it fuses a segmentation model's predicted label maps instead (seed 001's
pipeline: :mod:`generator.commands.fuse_predictions`).
"""

from __future__ import annotations

import logging
import os
from pathlib import Path

import numpy as np

from generator.atomic import atomic_path, staging, write_json, write_text
from generator.commands.fuse_predictions import add_prediction_args, run_predictions
from generator.commands.options import Integer, Number, path, sequence_id
from generator.commands.preflight import input_dir, output_dir
from generator.errors import UserError
from generator.jobs.plan import MAX_FRAME_INDEX
from generator.progress import progress

log = logging.getLogger(__name__)
#: Voxel edges the semantic map takes: below 5 cm its 19-bit voxel indices reach only
#: +-13 km and a map holds about one voxel per point anyway; above 50 m it says nothing.
MIN_VOXEL_M, MAX_VOXEL_M = 0.05, 50.0


def register(sub) -> None:
    p = sub.add_parser("fuse", help="project LiDAR into the images: label agreement report and 3D semantic map",
                       description=__doc__.split("\n\n")[1])
    p.add_argument("dataset", type=path, help="dataset folder with images/ and lidar/sequences/NN/")
    p.add_argument("--sequence", type=sequence_id, default="00", help="LiDAR sequence, 00..999999 (default 00)")
    p.add_argument("--abs-tol", type=Number(0, 10), default=None,
                   help="occlusion tolerance floor, metres, in [0, 10] (default 0.1)")
    p.add_argument("--rel-tol", type=Number(0, 1), default=None,
                   help="occlusion tolerance per metre of distance, in [0, 1] (default 0.01)")
    p.add_argument("--voxel", type=Number(MIN_VOXEL_M, MAX_VOXEL_M), default=0.2,
                   help=f"semantic-map voxel edge, metres, in [{MIN_VOXEL_M}, {MAX_VOXEL_M:g}] (default 0.2)")
    p.add_argument("--no-deskew", action="store_true", help="project the raw (motion-skewed) points")
    add_prediction_args(p)
    p.add_argument("--overlay-frame", type=Integer(0, MAX_FRAME_INDEX), default=None,
                   help="frame drawn in agreement.png (default: the one where the occlusion test rejects most "
                        "mislabelled points)")
    p.set_defaults(func=run)


def dataset_actors(root: Path, ds):
    """Instance id -> ``T_world_actor(t)`` of the moving actors of the dataset's spec, or None.

    The spec is the one ``generate``/``render`` recorded in ``root/manifest.json``; its world is
    rebuilt by :func:`generator.jobs.boxes.sequence_world` (as ``openlabel`` does: over the
    recorded duration, checked against the recorded digest). None without a manifest, without
    traffic, or for a sequence cast without actors.
    """
    from generator.imaging import meta_fields as md
    from generator.jobs import manifest as mf

    path = root / mf.NAME
    if not os.path.lexists(path):
        return None
    spec_doc = md.load_metadata(path).get("spec")  # a FIFO, a folder or bad JSON is one line
    if not isinstance(spec_doc, dict) or not isinstance(spec_doc.get("traffic"), dict):
        return None
    from generator.fusion.movers import actor_poses
    from generator.jobs.boxes import sequence_world
    from generator.layout.assemble import build_scene
    from generator.spec.load import parse_spec
    from generator.spec.towns import spec_for_record
    from generator.world.rig import Rig

    meta_src = str(ds.seq.dir / "lidar_meta.json")
    spec = spec_for_record(parse_spec(spec_doc, str(path)), ds.meta.get("scene"), meta_src)  # the sequence's town
    if not spec.traffic.enabled:
        return None
    log.info("rebuilding the traffic of %s to de-skew its moving actors", spec.name)
    times = ds.seq.times if ds.seq.times is not None else np.array([Rig.sweep_time(j) for j in ds.seq.frames])
    return actor_poses(sequence_world(spec, build_scene(spec), ds.meta, times, meta_src))


def run(args) -> int:
    if args.image_labels is not None:
        return run_predictions(args, dataset_actors)
    from generator.fusion import projection as P
    from generator.fusion.agreement import HEADLINE, Agreement, fuse_frame
    from generator.fusion.dataset import FusionDataset, deskewed
    from generator.fusion.report import markdown, report_png
    from generator.fusion.semantic_map import VoxelMap, write_map_ply, write_top_down

    abs_tol = P.ABS_TOL_M if args.abs_tol is None else args.abs_tol  # ranges checked when parsed
    rel_tol = P.REL_TOL if args.rel_tol is None else args.rel_tol
    root: Path = input_dir(args.dataset, what="dataset folder")
    out = output_dir(root / "fusion", "")
    ds = FusionDataset(root, args.sequence)
    overlay_k = args.overlay_frame
    if overlay_k is not None and overlay_k not in ds.frames:
        raise UserError(f"--overlay-frame: frame {overlay_k} has no image and scan "
                        f"(have {ds.frames[0]}..{ds.frames[-1]})")
    deskew = not args.no_deskew
    actors = dataset_actors(root, ds)
    movers = set(actors or ())
    agree, raw = Agreement(), Agreement()
    maps = {"lidar": VoxelMap(args.voxel), "camera": VoxelMap(args.voxel)}
    overlay, best, exact, timed = None, -1, True, True
    for frame in progress(ds, total=len(ds), desc="fuse", unit="frame"):
        fused = fuse_frame(frame, deskew, abs_tol, rel_tol, actors)
        agree.add(fused)
        if deskew and frame.times is not None:
            raw.add(fuse_frame(frame, False, abs_tol, rel_tol))
        exact &= frame.native_exact
        timed &= frame.times is not None
        world = P.transform(frame.pose, fused.xyz_start)  # Eq. 2, first-LiDAR frame
        maps["lidar"].add_static(world, frame.native, frame.semantic, frame.instance, movers)
        seen = fused.proj.index[fused.visible]
        maps["camera"].add_static(world[seen], fused.image_class[fused.visible], frame.semantic[seen],
                                  frame.instance[seen], movers)
        smeared = int((~fused.visible & (fused.image_class != fused.lidar_class)).sum())
        if frame.index == overlay_k or (overlay_k is None and smeared > best):
            overlay, best = (frame.class_id, fused), smeared
    # scans without an image still go into the LiDAR-labelled map
    for k in progress(ds.seq.frames, desc="map", unit="scan"):
        if k not in ds.paired_scans:
            scan = ds.read_scan(k)
            maps["lidar"].add_static(P.transform(scan["pose"], deskewed(scan, deskew, actors)), scan["native"],
                                     scan["semantic"], scan["instance"], movers)
    settings = {
        "dataset": str(root), "sequence": ds.seq.dir.name, "abs_tol_m": abs_tol, "rel_tol": rel_tol,
        "deskew": ("on (point_times/ + sweep poses of lidar_meta.json)" if deskew and timed else
                   "off (--no-deskew)" if not deskew else "off (the sequence has no point_times/)"),
        "lidar_classes": ("native, from native_labels/" if exact else
                          "canonical native class of the SemanticKITTI raw id (lossy: no native_labels/)"),
        "voxel_m": args.voxel,
        "moving_actors": (f"{len(movers)} actors of the spec in manifest.json: their points de-skewed by their own "
                          "motion, kept out of the semantic maps" if movers else "none"),
    }
    report = agree.to_dict(settings)
    if raw.frames:
        no_test = ("off",) + HEADLINE[1:]
        report["without_deskew"] = {"agreement_native": raw.agreement("native", HEADLINE),
                                    "agreement_native_no_occlusion_test": raw.agreement("native", no_test)}
    text = markdown(report)
    if raw.frames:
        text += (f"\nWithout de-skew (raw skewed points), the headline agreement is "
                 f"{100 * report['without_deskew']['agreement_native']:.2f} % (native).\n")
    positions = {k: (ds.poses[k][:3, 3] if ds.poses is not None else np.zeros(3)) for k in ds.seq.frames}
    trajectory = {"lidar": np.array([positions[k] for k in ds.seq.frames]),
                  "camera": np.array([positions[ds.scan_of[k]] for k in ds.frames])}
    with staging(out, "fusion") as stage:  # every file written in full before any is moved into place
        write_json(stage / "agreement.json", report)
        write_text(stage / "agreement.md", text)
        with atomic_path(stage / "agreement.png") as tmp:
            report_png(report, *overlay).save(tmp, format="PNG")
        for name, vm in maps.items():
            xyz, label, count = vm.voxels()
            if not len(xyz):
                log.warning("semantic map %s is empty", name)
                continue
            write_map_ply(stage / f"semantic_map_{name}.ply", xyz, label, count,
                          comment=f"urbangen semantic map ({name} labels), first LiDAR frame, voxel {args.voxel} m")
            write_top_down(stage / f"semantic_map_{name}.png", xyz, label, trajectory[name],
                           title=f"{ds.seq.dir.name}: {name} labels, "
                                 f"{len(ds.seq.frames) if name == 'lidar' else len(ds)} scans")
        for p in sorted(stage.iterdir()):
            os.replace(p, out / p.name)
    print(text.split("\n\n## ")[0].splitlines()[-1].strip("*"))
    print(f"wrote {out}/agreement.{{md,json,png}} and semantic_map_{{lidar,camera}}.{{ply,png}}")
    return 0
