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

import json
from pathlib import Path
from typing import Iterator

from generator.errors import UserError
from generator.formats.cityscapes import DEFAULT_SPLIT, SPLITS, CityscapesImage, city_name, export, image_stem

FORMATS = ("cityscapes",)


def register(sub) -> None:
    p = sub.add_parser("export", help="write a dataset's images in the Cityscapes layout",
                       description=__doc__.split("\n\n")[1])
    p.add_argument("format", choices=FORMATS, help="target layout: cityscapes")
    p.add_argument("dataset", type=Path, help="generated dataset (holds images/*.exr)")
    p.add_argument("out", type=Path, help="export root (leftImg8bit/ and gtFine/ are written inside)")
    p.add_argument("--split", default=DEFAULT_SPLIT, choices=SPLITS,
                   help=f"split folder: train, val or test (default {DEFAULT_SPLIT}, what cityscapesScripts evaluates)")
    p.set_defaults(func=run)


def _metadata(exr: Path) -> tuple[int, str, str]:
    path = exr.with_suffix(".json")
    try:
        meta = json.loads(path.read_text(encoding="utf-8"))
        return int(meta["frame"]), str(meta["time_of_day"]), str(meta["weather"]["kind"])
    except FileNotFoundError:
        raise UserError(f"{path}: missing (every image needs its metadata JSON)") from None
    except (json.JSONDecodeError, UnicodeDecodeError, KeyError, TypeError, ValueError) as e:
        raise UserError(f"{path}: not image metadata (frame, time_of_day, weather.kind): {e}") from None


def _sequence(dataset: Path) -> int:
    from generator.jobs.manifest import load

    manifest = load(dataset) or {}
    seq = str(manifest.get("plan", {}).get("sequence", "0"))
    if not seq.isdigit():
        raise UserError(f"{dataset / 'manifest.json'}: plan.sequence must be a number, got {seq!r}")
    return int(seq)


def run(args) -> int:
    from generator.progress import progress

    from generator.imaging.exr import read_exr
    from generator.previews.preview import camera_model_of, display_rgb

    if not args.dataset.is_dir():
        raise UserError(f"{args.dataset}: dataset folder not found")
    exrs = sorted((args.dataset / "images").glob("*.exr"))
    if not exrs:
        raise UserError(f"{args.dataset / 'images'}: no .exr images to export")
    if args.out.resolve() == args.dataset.resolve():
        raise UserError(f"{args.out}: output must differ from the dataset folder")
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
