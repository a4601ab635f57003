"""``urbangen export cityscapes|kitti-object|nuscenes|coco DIR OUT [--split train|val|test] [...]``.

Writes a generated dataset under OUT in the layout another ecosystem reads: cityscapes (the images,
scored by cityscapesScripts), kitti-object (the KITTI 3D object layout of the LiDAR sequences' stereo
pairs with their boxes, as OpenPCDet and MMDetection3D read it), nuscenes (the LiDAR sequences as a
nuScenes v1.0 dataroot with 2 Hz samples, 10 Hz sweeps and 3D boxes, loaded by nuscenes-devkit) or
coco (2D instance boxes and RLE masks of every image, plus COCO panoptic). Nothing is written on
error; existing files are never overwritten.

cityscapes: the images of DIR/images/*.exr (and their metadata JSON) in the
Cityscapes layout under OUT: leftImg8bit/<split>/<city>/<city>_<seq>_<frame>_leftImg8bit.png
(8-bit sRGB as the preview shows it: the camera model's response curve, or the
fixed tone mapping for images made without the model) and gtFine/<split>/<city>/..._gtFine_labelIds.png,
_instanceIds.png (label id x 1000 + k for person, rider and vehicles), _labelTrainIds.png and
_color.png. The weather x time variant of an image is its city (urbangen-day-clear,
urbangen-night-rain-fog, ...), so the 12 variants of a frame keep distinct names; <seq> is the
dataset's LiDAR sequence number. The default split is val, where cityscapesScripts'
evaluation looks.

kitti-object, nuscenes and coco live in their own modules (:mod:`generator.commands.export_kitti_object`,
:mod:`generator.commands.export_nuscenes`, :mod:`generator.commands.export_coco`); this one dispatches.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path

from generator.commands.options import Integer, Number, path, sequence_id, text_path
from generator.commands.preflight import input_dir, output_dir
from generator.errors import UserError
from generator.formats.cityscapes import DEFAULT_SPLIT, SPLITS, CityscapesImage, city_name, export, image_stem
from generator.imaging.paths import image_files, images_root
from generator.jobs.plan import MAX_FRAME_INDEX, check_free_space
from generator.safeload import MAX_METADATA_BYTES, load_json, printable
from generator.weather import TIMES, combinations

#: format -> the module whose ``run(args)`` writes it (None: this module, cityscapes)
FORMATS = {"cityscapes": None, "kitti-object": "generator.commands.export_kitti_object",
           "nuscenes": "generator.commands.export_nuscenes", "coco": "generator.commands.export_coco"}


def register(sub) -> None:
    p = sub.add_parser("export", help="write a dataset in the Cityscapes, KITTI 3D object, nuScenes or COCO layout",
                       description=__doc__.split("\n\n")[1])
    p.add_argument("format", choices=list(FORMATS), help="target layout: cityscapes, kitti-object, nuscenes or coco")
    p.add_argument("dataset", type=path, help="generated dataset (images/, lidar/sequences/)")
    p.add_argument("out", type=path, help="export root (the format's folders are written inside)")
    p.add_argument("--split", default=None, choices=SPLITS,
                   help=f"cityscapes: split folder (default {DEFAULT_SPLIT}, what cityscapesScripts evaluates); "
                        "nuscenes: the split every scene joins (default: each sequence's split in "
                        "lidar/semantic-kitti.yaml); coco: the name of the annotation files (default val)")
    p.add_argument("--spec", type=text_path, default=None,
                   help="nuscenes: the scene spec the dataset was made from, when it has no manifest.json "
                        "(made with 'urbangen lidar'); the boxes are rebuilt from it")
    p.add_argument("--sequences", nargs="+", type=sequence_id, default=None,
                   help="kitti-object: LiDAR sequences to export, 00..99 (default all)")
    p.add_argument("--min-points", type=Integer(0, 10_000_000), default=1,
                   help="kitti-object: things with fewer LiDAR points are DontCare regions (default 1)")
    p.add_argument("--val-share", type=Number(0.0, 1.0), default=0.5,
                   help="kitti-object: share of each sequence's samples in val.txt, its last ones (default 0.5)")
    p.set_defaults(func=run)


def _metadata(exr: Path) -> tuple[int, str, str]:
    path = exr.with_suffix(".json")
    if not os.path.lexists(path):
        raise UserError(f"{path}: missing (every image needs its metadata JSON)")
    meta = load_json(path, max_bytes=MAX_METADATA_BYTES, max_nodes=100_000)
    try:
        frame, tod, kind = meta["frame"], meta["time_of_day"], meta["weather"]["kind"]
    except (KeyError, TypeError):
        raise UserError(f"{path}: not image metadata (needs frame, time_of_day, weather.kind)") from None
    if type(frame) is not int or not 0 <= frame <= MAX_FRAME_INDEX:
        raise UserError(f"{path}: frame: must be an integer in 0..{MAX_FRAME_INDEX}")
    if not (
        isinstance(tod, str) and isinstance(kind, str) and (tod, kind) in set(combinations(TIMES))
    ):  # they name folders: known words only
        raise UserError(f"{path}: time_of_day, weather.kind: must be one of the known combinations "
                        f"({'/'.join(TIMES)} x {', '.join(sorted({w for _, w in combinations()}))})")
    return frame, tod, kind


def _sequence(dataset: Path) -> int:
    path = dataset / "manifest.json"
    manifest = load_json(path, max_bytes=MAX_METADATA_BYTES, max_nodes=10_000_000) if os.path.lexists(path) else {}
    plan = manifest.get("plan", {}) if isinstance(manifest, dict) else {}
    seq = str(plan.get("sequence", "0") if isinstance(plan, dict) else "?")
    if not (seq.isascii() and seq.isdigit() and len(seq) <= 6):
        raise UserError(f"{path}: plan.sequence must be a number, got {printable(seq, 40)!r}")
    return int(seq)


def run(args) -> int:
    if FORMATS[args.format] is not None:
        import importlib

        return importlib.import_module(FORMATS[args.format]).run(args)
    args.split = args.split or DEFAULT_SPLIT
    from generator.imaging.exr import read_exr
    from generator.previews.preview import camera_model_of, display_rgb
    from generator.progress import progress

    input_dir(args.dataset, what="dataset folder")
    output_dir(args.out, "OUT")
    exrs = image_files(args.dataset, "*.exr")
    if not exrs:
        raise UserError(f"{images_root(args.dataset)}: no .exr images to export")
    if args.out.resolve() == args.dataset.resolve():
        raise UserError(f"{args.out}: output must differ from the dataset folder")
    # five PNGs per image: about half the size of its EXR (RGB 8-bit, label ids compress well)
    check_free_space(args.out, sum(p.stat().st_size for p in exrs) // 2, f"{len(exrs)} images", flag="OUT")
    seq = _sequence(args.dataset)
    metas = [_metadata(p) for p in exrs]
    planned = [(city_name(t, w), image_stem(city_name(t, w), seq, f)) for f, t, w in metas]

    def images() -> Iterator[CityscapesImage]:
        for exr, (frame, time_of_day, weather) in progress(
            list(zip(exrs, metas, strict=False)), desc="export cityscapes", unit="image"
        ):
            im = read_exr(exr)
            yield CityscapesImage(str(exr), city_name(time_of_day, weather), seq, frame,
                                  display_rgb(im.rgb, camera_model_of(exr)), im.class_id, im.instance)

    written = export(images(), args.out, args.split, planned)
    cities = sorted({c for c, _ in planned})
    print(f"exported {len(written)} images to {args.out} ({args.split}; cities {', '.join(cities)})")
    return 0
