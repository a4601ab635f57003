"""Image statistics of a dataset: seed 003 Table I (annotated pixels per class) and Table II
(images per weather x time of day), plus a bar chart of the pixels per class.

Fast path: only the per-image metadata JSON (``DATASET/images/*.json``, ``classes_present``)
is read. :func:`verify` recomputes the pixel counts from the EXR masks and lists every image
whose metadata disagrees.

Table I rows are the seed-003 class names (native classes grouped by
``class_table().to_seed003()``, e.g. Trees = tree_trunk + tree_crown) plus the native classes
seed 003 had no name for, under their native names; sorted by total like the paper. The
average is over all images of the dataset (as in seed 003: total / number of images).
"""

from __future__ import annotations

import logging
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generator.errors import UserError
from generator.imaging import meta_fields as md
from generator.imaging.paths import image_files, images_root
from generator.labels import class_table
from generator.progress import progress
from generator.safeload import printable
from generator.stats.chart import log_bar_chart
from generator.stats.report import Figure, Section, Table
from generator.weather import DEFAULT_TIMES, KINDS, TIMES

log = logging.getLogger(__name__)

#: Table II row names, in KINDS order (seed 003 wording).
KIND_TITLES = {"clear": "Clear", "fog": "Fog", "rain": "Rain", "rain_fog": "Rain & fog", "wet": "Wet",
               "wet_fog": "Wet & fog"}
TIME_TITLES = {"day": "Day", "dusk": "Dusk", "night": "Night"}
CHART = "pixels_per_class.png"
#: Most pixels one class may claim in one image (a 65535 x 65535 image).
MAX_PIXELS = 65535 * 65535


@dataclass(frozen=True)
class ImageRecord:
    """What the statistics need from one image's metadata.

    Attributes
    ----------
    name : str
        Image name (file stem).
    source : Path
        The metadata JSON it came from.
    exr : Path or None
        The image's EXR (``files.exr``, relative to the JSON), None if not named.
    time_of_day : str
    weather : str
        Weather kind.
    pixels : (n_classes,) int64
        Pixels per native class id.
    size : int or None
        Width x height from the camera intrinsics, None if absent.
    """

    name: str
    source: Path
    exr: Path | None
    time_of_day: str
    weather: str
    pixels: np.ndarray
    size: int | None


@dataclass(frozen=True)
class ImageData:
    """The image records of one dataset (sorted by file name)."""

    root: Path
    records: list[ImageRecord]

    def totals(self) -> np.ndarray:
        """(n_classes,) int64 annotated pixels per native class over all images."""
        return np.sum([r.pixels for r in self.records], axis=0, dtype=np.int64)


def _bad(path: Path, reason: str) -> UserError:
    return UserError(f"{printable(path)}: {reason}")


def parse_record(path: Path, rec: object) -> ImageRecord:
    """One parsed metadata JSON -> :class:`ImageRecord`; a malformed record is a one-line UserError
    (naming the field, never quoting the file)."""
    if not isinstance(rec, dict):
        raise _bad(path, "metadata must be a JSON object")
    tod = rec.get("time_of_day")
    if tod not in TIMES:
        raise _bad(path, f"time_of_day: must be one of {', '.join(TIMES)}, got {md.kind_of(tod)}")
    weather = rec.get("weather")
    kind = weather.get("kind") if isinstance(weather, dict) else None
    if kind not in KINDS:
        raise _bad(path, f"weather.kind: must be one of {', '.join(KINDS)}, got {md.kind_of(kind)}")
    present = rec.get("classes_present")
    if not isinstance(present, dict) or not present:
        raise _bad(path, "classes_present: must be a non-empty object {class name: pixel count}")
    table = class_table()
    pixels = np.zeros(len(table), np.int64)
    for name, count in present.items():
        if name not in table.names:
            raise _bad(path, f"classes_present.{printable(name, 64)}: unknown class; known: {', '.join(table.names)}")
        if not isinstance(count, int) or isinstance(count, bool) or not 0 <= count <= MAX_PIXELS:
            raise _bad(path, f"classes_present.{name}: must be a pixel count (integer in [0, {MAX_PIXELS}]), "
                             f"got {md.kind_of(count) if not isinstance(count, int) else count}")
        pixels[table.id(name)] = count
    exr = md.exr_path(rec, path, must_exist=False) if isinstance(md.field(rec, "files.exr", str(path), None), str) \
        else None
    intr = (rec.get("camera") or {}).get("intrinsics") if isinstance(rec.get("camera"), dict) else None
    size = None
    if isinstance(intr, dict) and "width" in intr and "height" in intr:
        size = (md.integer(rec, "camera.intrinsics.width", str(path), 1, md.MAX_IMAGE_SIDE)
                * md.integer(rec, "camera.intrinsics.height", str(path), 1, md.MAX_IMAGE_SIDE))
    return ImageRecord(printable(path.stem, 200), path, exr, tod, kind, pixels, size)


def load(root: Path) -> ImageData | None:
    """Read every image's metadata, ``root/images/SSSS/*.json`` (:mod:`generator.imaging.paths`), through
    :mod:`generator.safeload` (the metadata limits).

    Returns
    -------
    ImageData or None
        None when ``root`` has no ``images/`` folder (the dataset has no camera images).

    Raises
    ------
    UserError
        If ``images/`` holds no metadata, or a metadata file is unreadable or malformed.
    """
    folder = images_root(root)
    if not folder.is_dir():
        return None
    paths = image_files(root, "*.json")
    if not paths:
        raise UserError(f"{folder}: no image metadata (*.json) found")
    records = []
    for p in progress(paths, desc="metadata", unit="img", leave=False):
        records.append(parse_record(p, md.load_metadata(p)))
    return ImageData(root, records)


def verify(data: ImageData) -> list[str]:
    """Recompute every image's pixel counts from its EXR masks.

    Returns
    -------
    list of str
        One line per image whose EXR is missing or unreadable, or whose counts differ from
        its metadata (naming the classes that differ); empty when all agree.
    """
    from generator.imaging.exr import read_exr  # OpenEXR only when verifying

    table = class_table()
    problems = []
    for r in progress(data.records, desc="verify", unit="img"):
        if r.exr is None:
            problems.append(f"{printable(r.source)}: files.exr is not given")
            continue
        if not os.path.lexists(r.exr):
            problems.append(f"{r.name}: files.exr names no file beside the metadata")
            continue
        try:
            class_id = read_exr(r.exr).class_id
        except UserError as e:
            problems.append(f"{r.name}: {e}")
            continue
        actual = np.bincount(class_id.ravel(), minlength=len(table)).astype(np.int64)
        diff = np.flatnonzero(actual != r.pixels)
        if diff.size:
            what = ", ".join(
                f"{table.names[i]} {int(r.pixels[i])} in metadata vs {int(actual[i])} in EXR" for i in diff
            )
            problems.append(f"{r.name}: {what}")
    return problems


# -- Table I -------------------------------------------------------------------------------

def pixel_groups() -> list[tuple[str, list[int], bool]]:
    """Table I rows: (row name, native class ids, is a seed-003 class), in class-table order."""
    table = class_table()
    groups: dict[str, tuple[list[int], bool]] = {}
    for i, s3 in enumerate(table.to_seed003()):
        key, is_s3 = (s3, True) if s3 is not None else (table.names[i], False)
        groups.setdefault(key, ([], is_s3))[0].append(i)
    return [(k, ids, s3) for k, (ids, s3) in groups.items()]


def table1(data: ImageData) -> Table:
    """Seed 003 Table I: annotated pixels per class, total and average per image."""
    n = len(data.records)
    totals = data.totals()
    names = class_table().names
    rows = []
    for name, ids, s3 in pixel_groups():
        total = int(totals[ids].sum())
        rows.append([name, total, total / n, " + ".join(names[i] for i in ids), s3])
    order = sorted(range(len(rows)), key=lambda k: -rows[k][1])  # stable: ties keep table order
    rows = [rows[k] for k in order]
    md = Table("table1_pixels", "Table I. Number of annotated pixels per class",
               ["Class", "Total", "Average per image", "Native classes", "Seed 003"],
               ["class", "total_pixels", "average_per_image", "native_classes", "seed003"],
               [[r[0], r[1], round(r[2], 2), r[3], r[4]] for r in rows],
               [f"Average = total / {n:,} images (as in seed 003). Seed 003 = no: a native class seed 003 "
                "had no name for, listed under its native name."])
    return md


# -- Table II ------------------------------------------------------------------------------

def table2(data: ImageData) -> Table:
    """Seed 003 Table II: images per weather (rows, KINDS order) x time of day, with totals.

    Columns: day and night (seed 003's), and dusk when the dataset has dusk images.
    """
    present = {r.time_of_day for r in data.records}
    times = [t for t in TIMES if t in DEFAULT_TIMES or t in present]
    counts = np.zeros((len(KINDS), len(times)), np.int64)
    for r in data.records:
        counts[KINDS.index(r.weather), times.index(r.time_of_day)] += 1
    rows = [[KIND_TITLES[k], *map(int, counts[i]), int(counts[i].sum())] for i, k in enumerate(KINDS)]
    rows.append(["Total", *map(int, counts.sum(0)), int(counts.sum())])
    ids = [*KINDS, "total"]
    return Table("table2_conditions",
                 "Table II. Distribution of images with respect to lighting and weather conditions",
                 ["Weather", *(TIME_TITLES[t] for t in times), "Total"],
                 ["weather", *times, "total"], rows, csv_rows=[[k, *r[1:]] for k, r in zip(ids, rows, strict=False)])


def chart(t1: Table) -> Figure:
    """Bar chart of Table I (log scale), bars in the class colours."""
    table = class_table()
    colours = []
    for row in t1.rows:
        first = row[3].split(" + ")[0]
        colours.append(tuple(int(c) for c in table.colors[table.id(first)]))
    png = log_bar_chart([r[0] for r in t1.rows], [r[1] for r in t1.rows], colours,
                        "Annotated pixels per class (total)", "pixels (log scale)")
    return Figure(CHART, "Annotated pixels per class, all images, log scale", png)


def section(data: ImageData) -> Section:
    """The images section of the report."""
    n = len(data.records)
    t1, t2 = table1(data), table2(data)
    summary = [f"{n:,} image{'s' if n != 1 else ''} from `{images_root(data.root)}` (metadata)",
               f"{int(data.totals().sum()):,} annotated pixels"]
    sized = [r for r in data.records if r.size is not None]
    partial = [r.name for r in sized if int(r.pixels.sum()) != r.size]
    if sized:
        if partial:
            summary.append(f"{len(partial)} image(s) whose class counts do not add up to width x height: "
                           + ", ".join(partial[:5]) + (" ..." if len(partial) > 5 else ""))
            log.warning("%d image(s) with class counts that do not cover the image, e.g. %s", len(partial), partial[0])
        else:
            summary.append("every pixel of every image is labelled (class counts add up to width x height)")
    return Section("Images", summary, [t1, t2], [chart(t1)])
