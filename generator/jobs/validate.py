"""Check a dataset folder file by file and list every problem found.

Each check returns a list of ``"<path>: <problem>"`` lines; an empty list means valid.
Every file is read through :mod:`generator.safeload` (regular files, size limits, strict
UTF-8 and JSON, finite numbers) and no check raises: a file that cannot be read is a
problem like any other, and no line quotes a file's content.

* Links: no symlink leads out of the dataset, none is a loop or dangling; no FIFO, socket
  or device inside it.
* Images: EXR channels present, masks binary / exclusive / complete, class names known,
  finite RGB, depth >= 0; metadata against its schema (types of every field), then what
  the readers use (pinhole K, rigid camera pose, the EXR beside it), and against the masks;
  every EXR with its JSON.
* LiDAR (:mod:`generator.jobs.validate_lidar`): scans, labels (ids in the label table,
  one per point), side files, poses (finite, rigid, one per scan), times (finite,
  increasing), calib, ``lidar_meta.json``.
* OpenLABEL: every file against the 1.0 schema. Manifest: every planned image present (the plan's frame
  ranges, manifest version 2, or its frame list, version 1).
"""

from __future__ import annotations

import errno
import os
import re
import stat
from pathlib import Path

import numpy as np

from generator.errors import UserError
from generator.imaging import meta_fields as md
from generator.imaging.exr import read_exr
from generator.imaging.metadata import class_pixels, validate_metadata
from generator.imaging.paths import find_image, frame_of, image_files, images_root, shard_name
from generator.jobs.validate_lidar import check_lidar, reason, rel
from generator.labels import class_table

#: OpenLABEL schema problems listed per file at most.
MAX_SCHEMA_PROBLEMS = 20
#: Missing planned images listed one by one at most (the rest are counted).
MAX_LISTED = 1_000
_NAME = re.compile(r"[a-z][a-z_]{0,31}")


def _read_json(path: Path, root: Path, problems: list[str]):
    """Parsed metadata JSON of ``path``, or None after recording why it cannot be read."""
    try:
        return md.load_metadata(path, rel(path, root))
    except UserError as e:
        problems.append(str(e))
        return None


def check_links(root: Path) -> list[str]:
    """Symlinks leading out of ``root``, symlink loops, dangling links and special files inside it."""
    base = os.path.realpath(root)
    problems = []
    for folder, dirs, files in os.walk(root, onerror=lambda e: problems.append(
            f"{rel(Path(e.filename or root), root)}: cannot list ({e.strerror or type(e).__name__})")):
        for name in sorted(dirs + files):
            p = Path(folder) / name
            try:
                mode = os.lstat(p).st_mode
            except OSError:
                continue
            if stat.S_ISLNK(mode):
                try:
                    os.stat(p)
                except OSError as e:
                    problems.append(f"{rel(p, root)}: symlink {'loop' if e.errno == errno.ELOOP else 'to nothing'}")
                    continue
                if os.path.commonpath([base, os.path.realpath(p)]) != base:
                    problems.append(f"{rel(p, root)}: symlink leading out of the dataset")
            elif not (stat.S_ISREG(mode) or stat.S_ISDIR(mode)):
                problems.append(f"{rel(p, root)}: not a regular file (a FIFO, socket or device)")
    return problems


#: Entries that must be folders when present (``NN`` stands for every sequence).
FOLDERS = ("images", "lidar", "lidar/sequences", "openlabel", "lidar/sequences/NN", "lidar/sequences/NN/velodyne",
           "lidar/sequences/NN/labels",
           "lidar/sequences/NN/native_labels", "lidar/sequences/NN/point_times")


def check_layout(root: Path) -> list[str]:
    """Entries of the dataset layout that exist but are not folders (a file, a FIFO, a broken link)."""
    seqs = root / "lidar" / "sequences"
    names = sorted(p.name for p in seqs.iterdir() if p.name.isdigit()) if seqs.is_dir() else []
    paths = [root / f for f in FOLDERS if "NN" not in f]
    paths += [root / f.replace("NN", n) for f in FOLDERS if "NN" in f for n in names]
    return [f"{rel(p, root)}: must be a folder" for p in paths if os.path.lexists(p) and not p.is_dir()]


def _image_meta(meta: dict, meta_path: Path, root: Path, img) -> list[str]:
    """What the readers use beyond the schema: pinhole K of the image's size, rigid pose, the EXR beside it."""
    src = rel(meta_path, root)
    problems = []
    try:
        _, w, h = md.intrinsics(meta, src)
        if (w, h) != (img.class_id.shape[1], img.class_id.shape[0]):
            problems.append(f"{src}: intrinsics size {w}x{h} differs from the image "
                            f"{img.class_id.shape[1]}x{img.class_id.shape[0]}")
        problem = md.rigid_problem(md.matrix(meta, "camera.T_world_camera", (4, 4), src))
        if problem:
            problems.append(f"{src}: camera.T_world_camera: {problem}")
        md.exr_path(meta, meta_path, src)
    except UserError as e:
        problems.append(str(e))
    if meta.get("classes_present") != class_pixels(img.class_id):
        problems.append(f"{src}: classes_present disagrees with the masks of the EXR")
    return problems


def check_images(root: Path) -> tuple[list[str], int]:
    """Problems of ``root/images`` (its shard folders, :mod:`generator.imaging.paths`, or the flat layout of
    older datasets) and the number of images checked."""
    problems: list[str] = []
    exrs = image_files(root, "*.exr")
    jsons = image_files(root, "*.json")
    for stem in sorted({p.with_suffix("") for p in jsons} - {p.with_suffix("") for p in exrs}):
        problems.append(f"{rel(stem, root)}.json: metadata without its EXR")
    base = images_root(root)
    for p in exrs + jsons:
        k = frame_of(p.name)
        if k is None:
            problems.append(f"{rel(p, root)}: not an image name (NNNNNN_<time>_<weather>)")
        elif p.parent != base and p.parent.name != shard_name(k):
            problems.append(f"{rel(p, root)}: in the wrong shard folder (frame {k} belongs in images/{shard_name(k)}/)")
    names = class_table().names
    for exr in exrs:
        r = rel(exr, root)
        try:
            img = read_exr(exr)
        except UserError as e:
            problems.append(f"{r}: {reason(e, exr)}")
            continue
        if str(img.header.get("urbangen.classes", ",".join(names))).split(",") != names:
            problems.append(f"{r}: class list in the header differs from the class table")
        if not np.isfinite(img.rgb).all():
            problems.append(f"{r}: RGB holds NaN or inf")
        if (img.depth < 0).any() or np.isnan(img.depth).any():
            problems.append(f"{r}: depth holds negative or NaN values")
        meta_path = exr.with_suffix(".json")
        if not os.path.lexists(meta_path):
            problems.append(f"{r}: no metadata JSON beside it")
            continue
        meta = _read_json(meta_path, root, problems)
        if meta is None:
            continue
        schema = [f"{rel(meta_path, root)}: {p}" for p in validate_metadata(meta)]
        problems += schema if schema else _image_meta(meta, meta_path, root, img)
    return problems, len(exrs)


def check_openlabel(root: Path) -> tuple[list[str], int]:
    from generator.formats.openlabel import openlabel_errors

    files = sorted((root / "openlabel").glob("*.json"))
    problems = []
    for f in files:
        doc = _read_json(f, root, problems)
        if doc is None:
            continue
        errors = [md.schema_message(e) for e in openlabel_errors(doc)]
        problems += [f"{rel(f, root)}: {p}" for p in errors[:MAX_SCHEMA_PROBLEMS]]
        if len(errors) > MAX_SCHEMA_PROBLEMS:
            problems.append(f"{rel(f, root)}: and {len(errors) - MAX_SCHEMA_PROBLEMS} more schema problems")
    return problems, len(files)


def check_boxes(root: Path) -> tuple[list[str], int]:
    """Every box file (``boxes/NN.npz``) reads back whole: arrays, shapes, finite numbers, row references."""
    from generator.errors import UserError
    from generator.formats.box_file import read_box_file

    files = sorted((root / "boxes").glob("*.npz")) if (root / "boxes").is_dir() else []
    problems = []
    for f in files:
        try:
            read_box_file(f)
        except UserError as e:
            problems.append(str(e).replace(str(root) + "/", "", 1))
    return problems, len(files)


def check_manifest(root: Path) -> list[str]:
    """Every image the manifest plans is present (its metadata JSON, written last). Reads a version 2 plan
    (``plan.frame_ranges``) or a version 1 one (``plan.frames``, every frame number)."""
    from generator.jobs.frameset import FrameSet

    p = root / "manifest.json"
    if not os.path.lexists(p):
        return []
    problems: list[str] = []
    m = _read_json(p, root, problems)
    if m is None:
        return problems
    plan = m.get("plan") if isinstance(m.get("plan"), dict) else {}
    combos = plan.get("combos")
    if "frame_ranges" in plan:
        try:
            frames = FrameSet.from_json(plan["frame_ranges"], 0, 10**6)
        except ValueError as e:
            return [f"manifest.json: plan.frame_ranges: {e}"]
    else:
        frames = plan.get("frames")
        if not (isinstance(frames, list) and all(isinstance(k, int) and not isinstance(k, bool) and 0 <= k < 10**6
                                                 for k in frames)):
            return ["manifest.json: plan.frames: must be a list of frame numbers"]
        frames = FrameSet.of(frames)
    if not (isinstance(combos, list) and all(isinstance(c, list) and len(c) == 2 and all(
            isinstance(x, str) and _NAME.fullmatch(x) for x in c) for c in combos)):
        return ["manifest.json: plan.combos: must be a list of [time_of_day, weather] names"]
    missing, n = [], 0
    for k in frames:
        for t, w in combos:
            if not find_image(root, f"{k:06d}_{t}_{w}", ".json").exists():
                n += 1
                if n <= MAX_LISTED:
                    missing.append(f"manifest.json: planned image {k:06d}_{t}_{w} is missing")
    if n > MAX_LISTED:
        missing.append(f"manifest.json: and {n - MAX_LISTED} more planned images are missing")
    return missing


def validate_dataset(root: Path) -> tuple[list[str], dict]:
    """Every problem of the dataset at ``root`` and how many items were checked."""
    links = check_links(root) + check_layout(root)
    images, n_img = check_images(root)
    lidar, n_scan = check_lidar(root)
    openlabel, n_ol = check_openlabel(root)
    boxes, n_box = check_boxes(root)
    return (links + images + lidar + openlabel + boxes + check_manifest(root),
            {"images": n_img, "scans": n_scan, "openlabel": n_ol, "box files": n_box})
