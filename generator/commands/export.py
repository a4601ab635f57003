"""``urbangen export cityscapes DIR OUT [--split train|val|test]``.

Writes the images of a generated dataset (DIR/images/*.exr and their metadata JSON) in the
Cityscapes layout under OUT: leftImg8bit/<split>/<city>/<city>_<seq>_<frame>_leftImg8bit.png
(8-bit sRGB as the preview shows it: the camera model's response curve, or the
fixed tone mapping for images made without the model) and gtFine/<split>/<city>/..._gtFine_labelIds.png,
_instanceIds.png (label id x 1000 + k for person, rider and vehicles), _labelTrainIds.png and
_color.png. The weather x time variant of an image is its city (urbangen-day-clear,
urbangen-night-rain-fog, ...), so the 12 variants of a frame keep distinct names; <seq> is the
dataset's LiDAR sequence number. The default split is val, where cityscapesScripts'
evaluation looks. Nothing is written on error; existing files are never overwritten.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Iterator

from generator.commands.options import path
from generator.commands.preflight import input_dir, output_dir
from generator.errors import UserError
from generator.imaging.paths import image_files, images_root
from generator.jobs.plan import MAX_FRAME_INDEX, check_free_space
from generator.safeload import MAX_METADATA_BYTES, load_json, printable
from generator.weather import TIMES, combinations
from generator.formats.cityscapes import DEFAULT_SPLIT, SPLITS, CityscapesImage, city_name, export, image_stem

FORMATS = ("cityscapes",)


def register(sub) -> None:
    p = sub.add_parser("export", help="write a dataset's images in the Cityscapes layout",
                       description=__doc__.split("\n\n")[1])
    p.add_argument("format", choices=FORMATS, help="target layout: cityscapes")
    p.add_argument("dataset", type=path, help="generated dataset (holds images/*.exr)")
    p.add_argument("out", type=path, help="export root (leftImg8bit/ and gtFine/ are written inside)")
    p.add_argument("--split", default=DEFAULT_SPLIT, choices=SPLITS,
                   help=f"split folder: train, val or test (default {DEFAULT_SPLIT}, what cityscapesScripts evaluates)")
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
    if not (isinstance(tod, str) and isinstance(kind, str) and (tod, kind) in set(combinations(TIMES))):  # they name folders: known words only
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
    from generator.progress import progress

    from generator.imaging.exr import read_exr
    from generator.previews.preview import camera_model_of, display_rgb

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
        for exr, (frame, time_of_day, weather) in progress(list(zip(exrs, metas)), desc="export cityscapes",
                                                           unit="image"):
            im = read_exr(exr)
            yield CityscapesImage(str(exr), city_name(time_of_day, weather), seq, frame,
                                  display_rgb(im.rgb, camera_model_of(exr)), im.class_id, im.instance)

    written = export(images(), args.out, args.split, planned)
    cities = sorted({c for c, _ in planned})
    print(f"exported {len(written)} images to {args.out} ({args.split}; cities {', '.join(cities)})")
    return 0
