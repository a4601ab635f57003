"""The processed twin of a dataset (``urbangen process DIR OUT --domain-gap seed002``).

Seed 002 evaluates detectors on raw and on processed synthetic scans of the *same* scenes. The twin
holds the same scenes, images, poses, calibration and boxes; only the scans differ: every scan of every
sequence goes through the seed 002 processing (:func:`generator.scan_effects.domain_gap.apply_domain_gap`:
random removal, per-axis jitter, constant intensity), and everything that counts points follows it:

* ``velodyne``, ``labels`` and the per-point side files (``point_times``, ``native_labels``,
  ``point_rings``) keep the same rows (the kept points, in order);
* ``lidar_meta.json``: ``points_per_scan``, ``raw_id_counts`` recounted, ``twin_of`` records the source,
  the parameters and the random stream; ``semantic-kitti.yaml``'s ``content`` recounted;
* the box file ``boxes/NN.npz`` and ``openlabel/NN.json``: every record's ``num_lidar_pts`` counted
  again in the processed labels (a ridden two-wheeler's rider and vehicle summed, from the box file's
  tracks); a box left with fewer points than the file's threshold leaves that sweep; image boxes keep
  their 2D boxes and visibility (the images do not change) with the new counts. Pure data: no spec,
  no rebuild.

Randomness: scan ``k`` of sequence ``NN`` draws from ``stream(seed, "process", "domain_gap", NN, k)``
of the sequence's own seed (``lidar_meta.json`` ``scene.seed``): a new stream, so the same source and
parameters give the same twin, byte for byte, and the source's own draws stay untouched.

Copied as they are (hard links where the file system allows): ``images/``, the stereo stream
(``image_2|3``, ``semantic_2|3``, ``passes_2|3``), ``poses.txt``, ``calib.txt``, ``times.txt``,
``manifest.json``. Derived pictures and reports (``bev/``, ``stats/``, ``fusion/``, range images, PLY)
are not: make them again on the twin.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import os
import shutil
from pathlib import Path

import numpy as np

from generator.atomic import staging
from generator.errors import UserError
from generator.formats import semantickitti as sk
from generator.formats.label_config import count_raw_ids, merge_counts
from generator.formats.point_sidecars import SIDECARS, read_sidecar
from generator.imaging import meta_fields as md
from generator.imaging.paths import images_root
from generator.rng import stream
from generator.scan_effects.domain_gap import SCALE_NOTE, DomainGap, apply_domain_gap

log = logging.getLogger(__name__)

META_NAME = "lidar_meta.json"
#: Sequence files and folders copied unchanged.
SEQUENCE_COPY = ("poses.txt", "calib.txt", "times.txt", "image_2", "image_3", "semantic_2", "semantic_3", "passes_2",
                 "passes_3")


def _link_or_copy(src: Path, dest: Path) -> None:
    dest.parent.mkdir(parents=True, exist_ok=True)
    if src.is_dir():
        for p in sorted(src.rglob("*")):
            if p.is_file():
                _link_or_copy(p, dest / p.relative_to(src))
        return
    try:
        os.link(src, dest)
    except OSError:
        shutil.copy2(src, dest)


def process_sequence(src: Path, dest: Path, gap: DomainGap, name: str) -> dict:
    """Write the processed twin of sequence folder ``src`` into ``dest``; its new ``lidar_meta.json``."""
    seq = sk.Sequence(src.parent.parent, name)
    meta = md.load_metadata(src / META_NAME)
    seed = md.integer(meta, "scene.seed", str(src / META_NAME), 0, 2**63 - 1)
    counts: dict[int, int] = {}
    n_points, records = [], []
    for k in seq.frames:
        pts, sem, inst = seq.read_labelled(k)
        sides = {f: read_sidecar(src, f, k, len(pts)) for f in SIDECARS}
        keep, xyz, rem, info = apply_domain_gap(pts[:, :3], pts[:, 3], gap,
                                                stream(seed, "process", "domain_gap", name, k))
        stem = f"{k:06d}"
        (dest / "velodyne").mkdir(parents=True, exist_ok=True)
        (dest / "labels").mkdir(parents=True, exist_ok=True)
        (dest / "velodyne" / f"{stem}.bin").write_bytes(sk.scan_array(xyz, rem).tobytes())
        (dest / "labels" / f"{stem}.label").write_bytes(sk.encode_labels(sem[keep], inst[keep]).astype("<u4")
                                                          .tobytes())
        for folder, values in sides.items():
            if values is not None:
                (dest / folder).mkdir(parents=True, exist_ok=True)
                (dest / folder / f"{stem}.bin").write_bytes(np.asarray(values[keep], SIDECARS[folder]).tobytes())
        n_points.append(int(len(keep)))
        counts = merge_counts(counts, count_raw_ids(sem[keep]))
        records.append({"frame": int(k), **info})
    for item in SEQUENCE_COPY:
        if (src / item).exists():
            _link_or_copy(src / item, dest / item)
    meta["points_per_scan"] = n_points
    meta["raw_id_counts"] = {str(k): int(v) for k, v in sorted(counts.items())}
    meta["twin_of"] = {"sequence": str(src), "processing": "seed 002 sec. 3.2 / 4.1.2 domain-gap processing",
                       "domain_gap": gap.to_dict(), "stream": f'stream(scene.seed, "process", "domain_gap", '
                                                              f'"{name}", frame)', "scans": records,
                       **({"scale_note": SCALE_NOTE} if gap.constant_intensity is not None else {})}
    (dest / META_NAME).write_text(json.dumps(meta, indent=1), encoding="utf-8")
    return meta


def _counts(seq_dir: Path, name: str) -> dict[int, dict[int, int]]:
    """Per sweep: points per instance id of the (processed) labels of ``seq_dir``."""
    from generator.detection import instance_counts

    seq = sk.Sequence(seq_dir.parent.parent, name)
    return {j: instance_counts(sk.read_labels(seq.label_path(j))[1]) for j in seq.frames}


def _instances_of(box_file) -> dict[int, tuple[int, ...]]:
    a = box_file.arrays if box_file is not None else None
    if a is None:
        return {}
    return {int(t): tuple(int(i) for i in ids if i > 0) for t, ids in zip(a["track_id"], a["track_instance_ids"],
                                                                         strict=True)}


def recount_box_file(src: Path, dest: Path, counts: dict[int, dict[int, int]]) -> dict:
    """Write ``src``'s box file to ``dest`` with every ``num_lidar_pts`` counted again from ``counts``."""
    from generator.formats.box_file import read_box_file, write_box_file

    bf = read_box_file(src)
    min_points = int(bf.info.get("min_points", 1))

    def n_of(r, j) -> int:
        return sum(counts.get(j, {}).get(i, 0) for i in r.instance_ids)

    records = [dataclasses.replace(r, num_lidar_pts=n_of(r, j)) for j in sorted(bf.sweeps) for r in bf.records(j)]
    kept = [r for r in records if r.num_lidar_pts >= min_points]
    images = []
    for name in bf.image_names:
        e = bf.image(name)
        boxes = [(dataclasses.replace(r, num_lidar_pts=n_of(r, e.sweep)) if e.sweep is not None and r.num_lidar_pts >= 0
                  else r, b) for r, b in e.boxes]
        images.append(dataclasses.replace(e, boxes=boxes))
    info = {**bf.info, "recounted": "num_lidar_pts counted again in the labels of the processed twin "
                                    "(urbangen process)"}
    dest.parent.mkdir(parents=True, exist_ok=True)
    write_box_file(dest, bf.sweeps, kept, images, info)
    return {"records": len(kept), "dropped": len(records) - len(kept)}


def recount_openlabel(src: Path, dest: Path, counts: dict[int, dict[int, int]], instances: dict) -> None:
    """Write ``src``'s OpenLABEL file to ``dest`` with ``lidar_points`` counted again (objects below the
    file's threshold leave their frame; frame intervals follow)."""
    from generator.formats.openlabel import POINTS_NAME, validate_openlabel

    doc = md.load_metadata(src)
    ol = doc.get("openlabel") if isinstance(doc, dict) else None
    if not isinstance(ol, dict) or not isinstance(ol.get("frames"), dict):
        raise UserError(f"{src}: not an OpenLABEL file urbangen wrote (openlabel.frames)")
    min_points = int(((ol.get("metadata") or {}).get("urbangen") or {}).get("min_points", 1))
    present: dict[str, list[int]] = {}
    for key, frame in ol["frames"].items():
        j = int(key)
        for uid in list(frame.get("objects") or {}):
            n = sum(counts.get(j, {}).get(i, 0) for i in instances.get(int(uid), (int(uid),)))
            nums = frame["objects"][uid].get("object_data", {}).get("num", [])
            if n < max(min_points, 1) or not nums:
                del frame["objects"][uid]
                continue
            for v in nums:
                if v.get("name") == POINTS_NAME:
                    v["val"] = int(n)
            present.setdefault(uid, []).append(j)
    objects = ol.get("objects") or {}
    for uid in list(objects):
        if uid not in present:
            del objects[uid]
        else:
            ks = sorted(present[uid])
            runs = np.split(np.array(ks), np.flatnonzero(np.diff(ks) > 1) + 1)
            objects[uid]["frame_intervals"] = [{"frame_start": int(r[0]), "frame_end": int(r[-1])} for r in runs]
    problems = validate_openlabel(doc)
    if problems:
        raise UserError(f"{src}: the recounted document does not match the OpenLABEL schema ({problems[0]})")
    dest.parent.mkdir(parents=True, exist_ok=True)
    dest.write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")


def process_dataset(root: Path, out: Path, gap: DomainGap, progress=None) -> dict:
    """Write the processed twin of dataset ``root`` into ``out`` (all at once or nothing)."""
    from generator.jobs.lidar_sequence import write_dataset_label_config
    from generator.progress import progress as bar

    progress = progress or bar
    root, out = Path(root), Path(out)
    names = [p.name for p in sorted((root / "lidar" / "sequences").glob("[0-9][0-9]")) if (p / META_NAME).is_file()]
    if not names:
        raise UserError(f"{root / 'lidar' / 'sequences'}: no LiDAR sequences (sequences/NN with {META_NAME})")
    for top in ("lidar", "images", "openlabel", "boxes", "manifest.json"):
        if os.path.lexists(out / top):
            raise UserError(f"{out / top}: exists; the twin goes into a new or empty folder")
    summary = {"sequences": names, "points_in": 0, "points_out": 0, "box_records": 0, "boxes_dropped": 0}
    with staging(out, "process") as stage:
        for name in progress(names, desc="process", unit="sequence"):
            src = root / "lidar" / "sequences" / name
            meta = process_sequence(src, stage / "lidar" / "sequences" / name, gap, name)
            summary["points_out"] += sum(meta["points_per_scan"])
            summary["points_in"] += sum(r["points_in"] for r in meta["twin_of"]["scans"])
            counts = _counts(stage / "lidar" / "sequences" / name, name)
            box_file = None
            if (root / "boxes" / f"{name}.npz").is_file():
                from generator.formats.box_file import read_box_file

                box_file = read_box_file(root / "boxes" / f"{name}.npz")
                n = recount_box_file(root / "boxes" / f"{name}.npz", stage / "boxes" / f"{name}.npz", counts)
                summary["box_records"] += n["records"]
                summary["boxes_dropped"] += n["dropped"]
            if (root / "openlabel" / f"{name}.json").is_file():
                recount_openlabel(root / "openlabel" / f"{name}.json", stage / "openlabel" / f"{name}.json", counts,
                                  _instances_of(box_file))
        split_cfg = root / "lidar" / "semantic-kitti.yaml"
        if split_cfg.is_file():
            shutil.copy2(split_cfg, stage / "lidar" / "semantic-kitti.yaml")   # its split, then new content
        write_dataset_label_config(stage / "lidar")
        if images_root(root).is_dir():
            _link_or_copy(images_root(root), images_root(stage))
        if (root / "manifest.json").is_file():
            shutil.copy2(root / "manifest.json", stage / "manifest.json")
        for top in sorted(stage.iterdir()):
            os.replace(top, out / top.name)
    return summary

