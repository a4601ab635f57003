"""``urbangen fuse DIR [--sequence NN] [--abs-tol M] [--rel-tol F] [--voxel M] [--no-deskew]``.

Projects every LiDAR scan of ``DIR/lidar/sequences/NN`` into its frame's image in
``DIR/images`` (seed 001 Eq. 1, de-skewed, with and without the occlusion test), compares
the mask class with each point's ray-cast class, and writes ``DIR/fusion/``:
``agreement.md``, ``agreement.json``, ``agreement.png`` (points over the labels coloured by
agreement, confusion matrices), and the semantic map of the sequence (seed 001 Eq. 2)
twice: ``semantic_map_lidar.{ply,png}`` (every point, its ray-cast class) and
``semantic_map_camera.{ply,png}`` (points the camera sees, labelled from the masks).
"""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np

from generator.atomic import write_json, write_text
from generator.errors import UserError
from generator.progress import progress

log = logging.getLogger(__name__)


def register(sub) -> None:
    p = sub.add_parser("fuse", help="project LiDAR into the images: label agreement report and 3D semantic map",
                       description=__doc__.split("\n\n")[1])
    p.add_argument("dataset", type=Path, help="dataset folder with images/ and lidar/sequences/NN/")
    p.add_argument("--sequence", default="00", help="LiDAR sequence (default 00)")
    p.add_argument("--abs-tol", type=float, default=None, help="occlusion tolerance floor, metres (default 0.1)")
    p.add_argument("--rel-tol", type=float, default=None, help="occlusion tolerance per metre of distance (default 0.01)")
    p.add_argument("--voxel", type=float, default=0.2, help="semantic-map voxel edge, metres (default 0.2)")
    p.add_argument("--no-deskew", action="store_true", help="project the raw (motion-skewed) points")
    p.add_argument("--overlay-frame", type=int, default=None,
                   help="frame drawn in agreement.png (default: the one where the occlusion test rejects most mislabelled points)")
    p.set_defaults(func=run)


def run(args) -> int:
    from generator.fusion import projection as P
    from generator.fusion.agreement import HEADLINE, Agreement, fuse_frame
    from generator.fusion.dataset import FusionDataset, deskewed
    from generator.fusion.report import markdown, report_png
    from generator.fusion.semantic_map import VoxelMap, write_map_ply, write_top_down
    from generator.formats.semantickitti import sequence_name

    abs_tol = P.ABS_TOL_M if args.abs_tol is None else args.abs_tol
    rel_tol = P.REL_TOL if args.rel_tol is None else args.rel_tol
    if not (0 <= abs_tol <= 10 and 0 <= rel_tol <= 1):
        raise UserError(f"--abs-tol must be in [0, 10] m and --rel-tol in [0, 1], got {abs_tol}, {rel_tol}")
    if args.voxel <= 0:
        raise UserError(f"--voxel: must be > 0, got {args.voxel}")
    root: Path = args.dataset
    if not root.is_dir():
        raise UserError(f"{root}: not a folder")
    ds = FusionDataset(root, sequence_name(args.sequence))
    overlay_k = args.overlay_frame
    if overlay_k is not None and overlay_k not in ds.frames:
        raise UserError(f"--overlay-frame: frame {overlay_k} has no image and scan (have {ds.frames[0]}..{ds.frames[-1]})")
    deskew = not args.no_deskew
    agree, raw = Agreement(), Agreement()
    maps = {"lidar": VoxelMap(args.voxel), "camera": VoxelMap(args.voxel)}
    overlay, best, exact, timed = None, -1, True, True
    for frame in progress(ds, total=len(ds), desc="fuse", unit="frame"):
        fused = fuse_frame(frame, deskew, abs_tol, rel_tol)
        agree.add(fused)
        if deskew and frame.times is not None:
            raw.add(fuse_frame(frame, False, abs_tol, rel_tol))
        exact &= frame.native_exact
        timed &= frame.times is not None
        world = P.transform(frame.pose, fused.xyz_start)  # Eq. 2, first-LiDAR frame
        maps["lidar"].add(world, frame.native)
        seen = fused.proj.index[fused.visible]
        maps["camera"].add(world[seen], fused.image_class[fused.visible])
        smeared = int((~fused.visible & (fused.image_class != fused.lidar_class)).sum())
        if frame.index == overlay_k or (overlay_k is None and smeared > best):
            overlay, best = (frame.class_id, fused), smeared
    # scans without an image still go into the LiDAR-labelled map
    for k in progress(ds.seq.frames, desc="map", unit="scan"):
        if k not in ds.frames:
            scan = ds.read_scan(k)
            maps["lidar"].add(P.transform(scan["pose"], deskewed(scan, deskew)), scan["native"])
    settings = {
        "dataset": str(root), "sequence": ds.seq.dir.name, "abs_tol_m": abs_tol, "rel_tol": rel_tol,
        "deskew": ("on (point_times/ + sweep poses of lidar_meta.json)" if deskew and timed else
                   "off (--no-deskew)" if not deskew else "off (the sequence has no point_times/)"),
        "lidar_classes": ("native, from native_labels/" if exact else
                          "canonical native class of the SemanticKITTI raw id (lossy: no native_labels/)"),
        "voxel_m": args.voxel,
    }
    report = agree.to_dict(settings)
    if raw.frames:
        report["without_deskew"] = {"agreement_native": raw.agreement("native", HEADLINE),
                                    "agreement_native_no_occlusion_test": raw.agreement("native", ("off",) + HEADLINE[1:])}
    out = root / "fusion"
    text = markdown(report)
    if raw.frames:
        text += (f"\nWithout de-skew (raw skewed points), the headline agreement is "
                 f"{100 * report['without_deskew']['agreement_native']:.2f} % (native).\n")
    write_json(out / "agreement.json", report)
    write_text(out / "agreement.md", text)
    from generator.atomic import atomic_path

    with atomic_path(out / "agreement.png") as tmp:
        report_png(report, *overlay).save(tmp, format="PNG")
    positions = {k: (ds.poses[k][:3, 3] if ds.poses is not None else np.zeros(3)) for k in ds.seq.frames}
    trajectory = {"lidar": np.array([positions[k] for k in ds.seq.frames]),
                  "camera": np.array([positions[k] for k in ds.frames])}
    for name, vm in maps.items():
        xyz, label, count = vm.voxels()
        if not len(xyz):
            log.warning("semantic map %s is empty", name)
            continue
        write_map_ply(out / f"semantic_map_{name}.ply", xyz, label, count,
                      comment=f"urbangen semantic map ({name} labels), first LiDAR frame, voxel {args.voxel} m")
        write_top_down(out / f"semantic_map_{name}.png", xyz, label, trajectory[name],
                       title=f"{ds.seq.dir.name}: {name} labels, {len(ds.seq.frames) if name == 'lidar' else len(ds)} scans")
    print(text.split("\n\n## ")[0].splitlines()[-1].strip("*"))
    print(f"wrote {out}/agreement.{{md,json,png}} and semantic_map_{{lidar,camera}}.{{ply,png}}")
    return 0
