"""``urbangen export coco DIR OUT [--split NAME]``: every image of a dataset as COCO instances and panoptic.

Written under ``OUT`` (COCO's layout; detectron2, MMDetection and pycocotools read it)::

    OUT/images/<split>/<stem>.png                  8-bit RGB as the preview shows it
    OUT/annotations/instances_<split>.json         thing segments: bbox, compressed RLE mask, area
    OUT/annotations/panoptic_<split>.json          segments_info per image (things and stuff)
    OUT/annotations/panoptic_<split>/<stem>.png    segment ids as R + 256 G + 256^2 B (0 = void)

Images: every image of ``images/`` (each weather x time variant; stem ``NNNNNN_<time>_<weather>``) and
the stereo stream of every LiDAR sequence (``passes_2|3`` with ``image_2|3``; stem
``seqNN_image_2_NNNNNN``). Categories and records: :mod:`generator.formats.coco`. Images carry
``urbangen`` fields naming their source (``source``, ``frame``, ``time_of_day``, ``weather``).
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

from PIL import Image

from generator.atomic import staging
from generator.errors import UserError
from generator.formats import coco as C
from generator.imaging.paths import images_root
from generator.labels.coco import coco_categories

DEFAULT_SPLIT = "val"
#: The export's own image folder (COCO's layout: ``images/<split>/NAME.png``), not a dataset's images/.
COCO_IMAGES = "images"


def image_sources(root: Path) -> list[tuple[str, str, object]]:
    """``(stem, kind, where)`` of every image: ``("images", name)`` of the dataset reader, or
    ``("stereo", (exr, png))`` of a sequence's stereo pair."""
    from generator.dataset import Dataset

    out = [(name, "images", name) for name in Dataset(root).image_names()] if images_root(root).is_dir() else []
    for seq in sorted((root / "lidar" / "sequences").glob("[0-9][0-9]")):
        for cam in (2, 3):
            for exr in sorted((seq / f"passes_{cam}").glob("[0-9]*.exr")):
                png = seq / f"image_{cam}" / f"{exr.stem}.png"
                if png.is_file():
                    out.append((f"seq{seq.name}_image_{cam}_{exr.stem}", "stereo", (exr, png)))
    if not out:
        raise UserError(f"{root}: no images to export (images/*.exr or lidar/sequences/NN/passes_2/*.exr)")
    return out


def _load(ds, kind: str, where):
    """(rgb uint8 or a PNG path to copy, class_id, instance, urbangen info) of one image (``ds``: the
    dataset reader)."""
    if kind == "images":
        from generator.previews.preview import display_rgb

        img = ds.image(where)
        meta = img.meta
        info = {"source": f"images/{where}.exr", "frame": meta.get("frame"), "time_of_day": meta.get("time_of_day"),
                "weather": (meta.get("weather") or {}).get("kind")}
        return display_rgb(img.rgb, meta.get("camera_model")), img.class_id, img.instance, info
    from generator.imaging.exr import read_exr

    exr, png = where
    img = read_exr(exr)
    return png, img.class_id, img.instance, {"source": str(Path(*exr.parts[-4:])), "frame": int(exr.stem)}


def export_coco(root: Path, out: Path, split: str = DEFAULT_SPLIT, progress=None) -> dict:
    """Write the COCO instance and panoptic files of every image of ``root`` under ``out`` (all or nothing).

    Returns
    -------
    dict
        ``images``, ``annotations`` (instances), ``segments`` (panoptic) counts and the files written.
    """
    from generator.progress import progress as bar

    progress = progress or bar
    C.mask_api()                                  # one line if pycocotools is missing, before any work
    root, out = Path(root), Path(out)
    sources = image_sources(root)
    targets = [out / "annotations" / f"instances_{split}.json", out / "annotations" / f"panoptic_{split}.json",
               out / COCO_IMAGES / split, out / "annotations" / f"panoptic_{split}"]
    for t in targets:
        if os.path.lexists(t):
            raise UserError(f"{t}: exists; remove it or choose another output folder")
    cats = coco_categories()
    from generator.dataset import Dataset

    ds = Dataset(root)
    images, anns, pan = [], [], []
    with staging(out, "coco") as stage:
        img_dir, pan_dir = stage / COCO_IMAGES / split, stage / "annotations" / f"panoptic_{split}"
        img_dir.mkdir(parents=True)
        pan_dir.mkdir(parents=True)
        for image_id, (stem, kind, where) in enumerate(progress(sources, desc="export coco", unit="image"), start=1):
            rgb, cls, inst, info = _load(ds, kind, where)
            h, w = cls.shape
            if isinstance(rgb, Path):
                shutil.copyfile(rgb, img_dir / f"{stem}.png")
            else:
                Image.fromarray(rgb).save(img_dir / f"{stem}.png")
            images.append({"id": image_id, "file_name": f"{stem}.png", "width": int(w), "height": int(h),
                           "urbangen": info})
            anns += C.instance_annotations(image_id, cls, inst, len(anns) + 1)
            png, segments = C.panoptic(cls, inst)
            Image.fromarray(png).save(pan_dir / f"{stem}.png")
            pan.append({"image_id": image_id, "file_name": f"{stem}.png", "segments_info": segments})
        about = {"description": f"urbangen dataset {root.name}: COCO {split}", "version": "1.0",
                 "contributor": "urbangen", "url": "", "year": 2020, "date_created": "2020-01-01"}
        instances = {"info": about, "licenses": [], "images": images, "annotations": anns,
                     "categories": [{k: c[k] for k in ("id", "name", "supercategory")} for c in cats if c["isthing"]]}
        panoptic = {"info": about, "licenses": [], "images": images, "annotations": pan,
                    "categories": [{k: c[k] for k in ("id", "name", "supercategory", "isthing", "color")}
                                   for c in cats]}
        (stage / "annotations" / f"instances_{split}.json").write_text(json.dumps(instances), encoding="utf-8")
        (stage / "annotations" / f"panoptic_{split}.json").write_text(json.dumps(panoptic), encoding="utf-8")
        for t in targets:                       # checked free above; staged whole: move in
            t.parent.mkdir(parents=True, exist_ok=True)
            os.replace(stage / t.relative_to(out), t)
    return {"images": len(images), "annotations": len(anns), "segments": sum(len(p["segments_info"]) for p in pan),
            "files": [str(t) for t in targets], "categories": sorted({a["category_id"] for a in anns})}

