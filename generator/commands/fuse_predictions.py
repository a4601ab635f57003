"""``urbangen fuse DIR --image-labels PRED [--label-set SET|FILE.yaml] [--map-set SET]``: seed 001's pipeline.

A segmentation model's predicted label maps (PNGs in PRED, any depth) are found for the images of
sequence NN -- the seed-003 images by the Cityscapes stem of their export (``<city>_<seq>_<frame>*.png``,
as cityscapesScripts finds results), the KITTI stream by ``image_2`` file name -- projected onto the scans
with fuse's projection and occlusion test, and written to ``DIR/fusion/``:
``predicted/sequences/NN/predictions/*.label`` (SemanticKITTI raw ids of the predicted classes, 0 for
points no image labels; every scan of the sequence, so semantic-kitti-api and ``urbangen eval`` read the
tree), ``predictions.json`` and ``predictions.md`` (IoU per class of the labelled points and of the
semantic map against the LiDAR ground truth, in every label set the prediction determines), and the
semantic map from the predictions in --map-set classes (default seed001, the paper's 8) beside the one
from the LiDAR labels of the same points: ``semantic_map_predicted.{ply,png}``,
``semantic_map_predicted_truth.{ply,png}``, ``semantic_map_predicted_vs_truth.png``.
"""

from __future__ import annotations

import os
from collections import defaultdict
from pathlib import Path

import numpy as np

from generator.atomic import staging, write_json, write_text
from generator.commands.options import path
from generator.commands.preflight import input_dir, output_dir
from generator.errors import UserError
from generator.progress import progress

PRED_TREE = "predicted"


def add_prediction_args(p) -> None:
    """The options of the prediction pipeline."""
    from generator.labels.class_sets import BUILTIN

    p.add_argument("--image-labels", type=path, default=None, metavar="PRED",
                   help="fuse a model's predicted label maps (PNGs in PRED) instead of the rendered masks: "
                        "SemanticKITTI .label tree, scores against the LiDAR labels, semantic map")
    p.add_argument("--label-set", default="cityscapes", metavar="SET",
                   help=f"--image-labels: what the predicted pixel values are: {', '.join(BUILTIN)} or a label-set "
                        "YAML file (default cityscapes: Cityscapes label ids)")
    p.add_argument("--map-set", default="seed001", metavar="SET",
                   help="--image-labels: classes of the semantic map (default seed001: the paper's 8 merged "
                        "classes; any set the prediction determines)")


def _targets(pred_set) -> dict:
    from generator.labels.class_sets import BUILTIN, builtin_sets, compatible_sets

    out = {name: (builtin_sets()[name], lut) for name, lut in compatible_sets(pred_set).items()}
    if pred_set.name not in BUILTIN:  # a user's set is also scored in its own classes
        out[pred_set.name] = (pred_set, np.arange(pred_set.size))
    return out


def run_predictions(args, actors_of) -> int:
    """Run the pipeline.

    ``actors_of(root, ds)`` gives the moving actors' poses (:func:`generator.commands.fuse.dataset_actors`);
    passed in so this module does not import ``fuse``, which imports it.
    """
    from generator.formats import semantickitti as sk
    from generator.formats.cityscapes_stems import dataset_sequence
    from generator.formats.prediction_files import PredictionFolder
    from generator.fusion import projection as P
    from generator.fusion.dataset import FusionDataset, deskewed
    from generator.fusion.prediction_report import markdown, palette, save_png, side_by_side, write_label_ply
    from generator.fusion.prediction_score import PredictionScore, fuse_scan, score_maps
    from generator.fusion.prediction_views import ViewProjector, find_views
    from generator.fusion.semantic_map import VoxelMap
    from generator.labels.class_sets import load_class_set, semantickitti_raw

    pred_set = load_class_set(args.label_set)
    targets = _targets(pred_set)
    if args.map_set not in targets:
        raise UserError(f"--map-set: {args.map_set!r} is not a label set the prediction ({pred_set.name}) "
                        f"determines; choose one of {', '.join(targets)}")
    root: Path = input_dir(args.dataset, what="dataset folder")
    input_dir(args.image_labels, "--image-labels")
    folder = PredictionFolder(args.image_labels)
    out = output_dir(root / "fusion", "")
    ds = FusionDataset(root, args.sequence, images=False)
    views = find_views(ds, folder, dataset_sequence(root))
    if not views:
        raise UserError(f"{args.image_labels}: --image-labels: no prediction for any image of sequence "
                        f"{ds.seq.dir.name} (expected Cityscapes stems like urbangen-day-clear_000000_000000*.png "
                        "or image_2 names like 000000.png)")
    deskew = not args.no_deskew
    actors = actors_of(root, ds) if deskew else None
    movers = set(actors or ())
    abs_tol = P.ABS_TOL_M if args.abs_tol is None else args.abs_tol
    rel_tol = P.REL_TOL if args.rel_tol is None else args.rel_tol
    projector = ViewProjector(ds, pred_set, deskew, abs_tol, rel_tol, actors)
    score = PredictionScore(targets)
    map_set, map_lut = targets[args.map_set]
    maps = {"predicted": VoxelMap(args.voxel), "truth": VoxelMap(args.voxel)}
    raw_of = semantickitti_raw(pred_set)
    by_scan = defaultdict(list)
    for v in views:
        by_scan[v.scan].append(v)
    seq_name = ds.seq.dir.name
    tree = Path(PRED_TREE) / "sequences" / seq_name / "predictions"
    positions = []
    with staging(out, "fusion-predictions") as stage:
        for k in progress(ds.seq.frames, desc="fuse predictions", unit="scan"):
            if k not in by_scan:  # no image: every point unlabelled
                n = os.stat(ds.seq.scan_path(k)).st_size // 16
                sk.write_labels(stage / tree / f"{k:06d}.label", np.zeros(n, np.uint16), np.zeros(n, np.uint16))
                continue
            scan = ds.read_scan(k)
            native = scan["native"]
            fused = fuse_scan(len(native), native, [projector.project(v) for v in by_scan[k]])
            score.add(k, native, fused)
            lab = fused.label["on"]
            keep = lab >= 0
            sk.write_labels(stage / tree / f"{k:06d}.label", np.where(keep, raw_of[np.maximum(lab, 0)], 0),
                            np.zeros(len(lab), np.uint16))
            world = P.transform(scan["pose"], deskewed(scan, deskew, actors))[keep]
            sem, inst = scan["semantic"][keep], scan["instance"][keep]
            maps["predicted"].add_static(world, map_lut[lab[keep]], sem, inst, movers)
            maps["truth"].add_static(world, map_set.from_native[native[keep]], sem, inst, movers)
            positions.append(scan["pose"][:3, 3])
        xyz, pred_lab, count = maps["predicted"].voxels()
        _, truth_lab, _ = maps["truth"].voxels()  # the same points, so the same voxels in the same order
        if not len(xyz):
            raise UserError(f"{args.image_labels}: the predictions label no static point of sequence {seq_name}")
        report = _report(args, root, ds, pred_set, views, score, score_maps(pred_lab, truth_lab, map_set),
                         deskew, abs_tol, rel_tol)
        colors = palette(map_set)
        for name, lab in (("predicted", pred_lab), ("predicted_truth", truth_lab)):
            write_label_ply(stage / f"semantic_map_{name}.ply", xyz, lab, count, colors,
                            f"urbangen semantic map ({name}, {map_set.name} classes), first LiDAR frame")
        traj = np.array(positions)
        title = (f"{seq_name}: semantic map from {pred_set.name} predictions ({len(views)} images), {map_set.name} "
                 f"classes; map mIoU {_pct(report['map']['miou_present'])} % over present classes")
        save_png(stage / "semantic_map_predicted_vs_truth.png", side_by_side(xyz, pred_lab, truth_lab, map_set, traj,
                                                                             title))
        write_json(stage / "predictions.json", report)
        write_text(stage / "predictions.md", markdown(report))
        for p in sorted(stage.rglob("*")):
            if p.is_file():
                dest = out / p.relative_to(stage)
                dest.parent.mkdir(parents=True, exist_ok=True)
                os.replace(p, dest)
    hv = report["headline"]
    print(f"{len(views)} images on {len(report['scans'])} scans: {hv['labelled_points']} points labelled; "
          f"{map_set.name} mIoU {_pct(hv['miou_present'])} % (present classes) on the labelled points, "
          f"map {_pct(report['map']['miou_present'])} %")
    print(f"wrote {out}/predictions.{{md,json}}, {out / tree}/ and semantic_map_predicted*.{{ply,png}}")
    return 0


def _pct(x) -> str:
    return "–" if x is None else f"{100 * x:.2f}"


def _report(args, root, ds, pred_set, views, score, map_scores, deskew, abs_tol, rel_tol) -> dict:
    from generator.fusion.prediction_score import HEADLINE, variant_key

    pts = score.to_dict()
    head = pts[args.map_set][variant_key(HEADLINE)]
    paired = score.points
    return {
        "settings": {"dataset": str(root), "sequence": ds.seq.dir.name, "predictions": str(args.image_labels),
                     "label_set": pred_set.name, "label_set_source": pred_set.source, "map_set": args.map_set,
                     "abs_tol_m": abs_tol, "rel_tol": rel_tol, "voxel_m": args.voxel,
                     "deskew": "on" if deskew else "off (--no-deskew)",
                     "lidar_truth": "native_labels/ side files" if all(
                         os.path.lexists(ds.seq.dir / "native_labels" / f"{k:06d}.bin") for k in score.scans)
                     else "canonical native class of the SemanticKITTI raw id (lossy: no native_labels/)"},
        "views": [{"image": v.name, "kind": v.kind, "scan": v.scan, "prediction": str(v.prediction)} for v in views],
        "scans": score.scans,
        "coverage": {"points": paired, "labelled_occlusion_on": score.labelled["on"],
                     "labelled_occlusion_off": score.labelled["off"],
                     "share_on": score.labelled["on"] / paired if paired else None},
        "headline": {"label_set": args.map_set, "variant": variant_key(HEADLINE), "labelled_points": head["points"],
                     "miou": head["miou"], "miou_present": head["miou_present"], "accuracy": head["accuracy"]},
        "points": pts,
        "map": map_scores,
    }
