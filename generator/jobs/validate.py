"""Check a dataset folder file by file and list every problem found.

Each check returns a list of ``"<path>: <problem>"`` lines; an empty list means valid.
Images: EXR channels present, masks binary / exclusive / complete, class list, finite
RGB, metadata against its schema and against the masks, every EXR with its JSON.
LiDAR: ``.bin`` / ``.label`` sizes, labels in the label table, poses, times and calib.
OpenLABEL: every file against the 1.0 schema. Manifest: every planned item present.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from generator.errors import UserError
from generator.imaging.exr import read_exr
from generator.imaging.metadata import class_pixels, validate_metadata
from generator.labels import class_table


def _rel(path: Path, root: Path) -> str:
    try:
        return str(path.relative_to(root))
    except ValueError:
        return str(path)


def _read_json(path: Path, root: Path, problems: list[str]):
    """Parsed JSON of ``path``, or None after recording why it cannot be read."""
    try:
        return json.loads(path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as e:
        problems.append(f"{_rel(path, root)}: invalid JSON ({e})")
        return None


def check_images(root: Path) -> tuple[list[str], int]:
    """Problems of ``root/images`` and the number of images checked."""
    folder = root / "images"
    problems: list[str] = []
    exrs = sorted(folder.glob("*.exr"))
    jsons = sorted(p for p in folder.glob("*.json"))
    for stem in sorted({p.stem for p in jsons} - {p.stem for p in exrs}):
        problems.append(f"{_rel(folder / stem, root)}.json: metadata without its EXR")
    for exr in exrs:
        rel = _rel(exr, root)
        try:
            img = read_exr(exr)
        except UserError as e:
            problems.append(f"{rel}: {str(e).split(': ', 1)[-1]}")
            continue
        classes = img.header.get("urbangen.classes", "")
        if classes.split(",") != class_table().names:
            problems.append(f"{rel}: class list in the header differs from the class table")
        if not np.isfinite(img.rgb).all():
            problems.append(f"{rel}: RGB holds NaN or inf")
        if (img.depth < 0).any() or np.isnan(img.depth).any():
            problems.append(f"{rel}: depth holds negative or NaN values")
        meta_path = exr.with_suffix(".json")
        if not meta_path.exists():
            problems.append(f"{rel}: no metadata JSON beside it")
            continue
        meta = _read_json(meta_path, root, problems)
        if meta is None:
            continue
        problems += [f"{_rel(meta_path, root)}: {p}" for p in validate_metadata(meta)]
        if isinstance(meta, dict) and meta.get("classes_present") not in (None, class_pixels(img.class_id)):
            problems.append(f"{_rel(meta_path, root)}: classes_present disagrees with the masks of the EXR")
        w, h = img.class_id.shape[1], img.class_id.shape[0]
        intr = meta.get("camera", {}).get("intrinsics", {}) if isinstance(meta, dict) else {}
        if intr and (intr.get("width"), intr.get("height")) != (w, h):
            problems.append(f"{_rel(meta_path, root)}: intrinsics size {intr.get('width')}x{intr.get('height')} "
                            f"differs from the image {w}x{h}")
    return problems, len(exrs)


def check_lidar(root: Path) -> tuple[list[str], int]:
    """Problems of every sequence under ``root/lidar`` and the number of scans checked."""
    from generator.formats import kitti_calib
    from generator.formats.semantickitti import list_sequences, read_labels, read_poses, read_times

    lidar = root / "lidar"
    if not (lidar / "sequences").is_dir():
        return [], 0
    known = set(class_table().sk_labels)
    problems, n = [], 0
    for name in list_sequences(lidar):
        seq = lidar / "sequences" / name
        bins = sorted((seq / "velodyne").glob("*.bin"))
        n += len(bins)
        for b in bins:
            lab = seq / "labels" / (b.stem + ".label")
            size = b.stat().st_size
            if size % 16:
                problems.append(f"{_rel(b, root)}: size {size} is not a multiple of 16 bytes (x, y, z, remission float32)")
                continue
            if not lab.exists():
                problems.append(f"{_rel(b, root)}: no labels/{b.stem}.label")
                continue
            if lab.stat().st_size != size // 4:
                problems.append(f"{_rel(lab, root)}: {lab.stat().st_size // 4} labels for {size // 16} points")
                continue
            sem, _ = read_labels(lab)
            bad = sorted(set(np.unique(sem).tolist()) - known)
            if bad:
                problems.append(f"{_rel(lab, root)}: label ids {bad} are not in the label table")
        for fname, reader in (("poses.txt", read_poses), ("times.txt", read_times)):
            p = seq / fname
            try:
                rows = len(reader(p))
            except (UserError, OSError) as e:
                problems.append(f"{_rel(p, root)}: {str(e).split(': ', 1)[-1]}")
                continue
            if rows != len(bins):
                problems.append(f"{_rel(p, root)}: {rows} rows for {len(bins)} scans")
        try:
            calib = kitti_calib.read_calib(seq / "calib.txt")
            missing = [k for k in ("P0", "P1", "P2", "P3", "Tr") if k not in calib]
            if missing:
                problems.append(f"{_rel(seq / 'calib.txt', root)}: missing {', '.join(missing)}")
        except (UserError, OSError, ValueError) as e:
            problems.append(f"{_rel(seq / 'calib.txt', root)}: {str(e).split(': ', 1)[-1]}")
    return problems, n


def check_openlabel(root: Path) -> tuple[list[str], int]:
    from generator.formats.openlabel import validate_openlabel

    files = sorted((root / "openlabel").glob("*.json"))
    problems = []
    for f in files:
        doc = _read_json(f, root, problems)
        if doc is None:
            continue
        problems += [f"{_rel(f, root)}: {p}" for p in validate_openlabel(doc)]
    return problems, len(files)


def check_manifest(root: Path) -> list[str]:
    p = root / "manifest.json"
    if not p.exists():
        return []
    try:
        m = json.loads(p.read_text())
        frames, combos = m["plan"]["frames"], m["plan"]["combos"]
    except (json.JSONDecodeError, KeyError, TypeError, UnicodeDecodeError) as e:
        return [f"manifest.json: unreadable ({e})"]
    missing = [f"{k:06d}_{t}_{w}" for k in frames for t, w in combos
               if not (root / "images" / f"{k:06d}_{t}_{w}.json").exists()]
    return [f"manifest.json: planned image {n} is missing" for n in missing]


def validate_dataset(root: Path) -> tuple[list[str], dict]:
    """Every problem of the dataset at ``root`` and how many items were checked."""
    images, n_img = check_images(root)
    lidar, n_scan = check_lidar(root)
    openlabel, n_ol = check_openlabel(root)
    return images + lidar + openlabel + check_manifest(root), {"images": n_img, "scans": n_scan, "openlabel": n_ol}
