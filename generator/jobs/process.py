"""The processed twin of a dataset (``urbangen process DIR OUT --domain-gap seed002``).

Seed 002 evaluates detectors on raw and on processed synthetic scans of the *same* scenes. The twin
holds the same scenes, images, poses, calibration and boxes; only the scans differ: every scan of every
sequence goes through the seed 002 processing (:func:`generator.scan_effects.domain_gap.apply_domain_gap`:
random removal, per-axis jitter, constant intensity), and everything that counts points follows it:

* ``velodyne``, ``labels`` and the per-point side files (``point_times``, ``native_labels``,
  ``point_rings``) keep the same rows (the kept points, in order);
* ``lidar_meta.json``: ``points_per_scan``, ``raw_id_counts`` recounted, ``twin_of`` records the source,
  the parameters and the random stream; ``semantic-kitti.yaml``'s ``content`` recounted;
* ``openlabel/NN.json`` rewritten from the spec with ``num lidar_points`` counted in the processed
  labels (an object left without points leaves that frame); the box records of the exports count
  points in the labels they read, so they follow by themselves.

Randomness: scan ``k`` of sequence ``NN`` draws from ``stream(seed, "process", "domain_gap", NN, k)``
of the sequence's own seed (``lidar_meta.json`` ``scene.seed``): a new stream, so the same source and
parameters give the same twin, byte for byte, and the source's own draws stay untouched.

Copied as they are (hard links where the file system allows): ``images/``, the stereo stream
(``image_2|3``, ``semantic_2|3``, ``passes_2|3``), ``poses.txt``, ``calib.txt``, ``times.txt``,
``manifest.json``. Derived pictures and reports (``bev/``, ``stats/``, ``fusion/``, range images, PLY)
are not: make them again on the twin.
"""

from __future__ import annotations

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


def process_dataset(root: Path, out: Path, gap: DomainGap, spec=None, progress=None) -> dict:
    """Write the processed twin of dataset ``root`` into ``out`` (all at once or nothing).

    Parameters
    ----------
    spec : generator.spec.SceneSpec, optional
        The dataset's spec, to rewrite ``openlabel/NN.json`` with recounted points (needed only when the
        dataset has OpenLABEL files).
    """
    from generator.jobs.lidar_sequence import write_dataset_label_config
    from generator.progress import progress as bar

    progress = progress or bar
    root, out = Path(root), Path(out)
    names = [p.name for p in sorted((root / "lidar" / "sequences").glob("[0-9][0-9]")) if (p / META_NAME).is_file()]
    if not names:
        raise UserError(f"{root / 'lidar' / 'sequences'}: no LiDAR sequences (sequences/NN with {META_NAME})")
    for top in ("lidar", "images", "openlabel", "manifest.json"):
        if os.path.lexists(out / top):
            raise UserError(f"{out / top}: exists; the twin goes into a new or empty folder")
    labelled = [n for n in names if (root / "openlabel" / f"{n}.json").is_file()]
    if labelled and spec is None:
        raise UserError(f"{root / 'openlabel'}: rewriting the OpenLABEL boxes needs the dataset's spec "
                        "(manifest.json, or name it with --spec)")
    summary = {"sequences": names, "points_in": 0, "points_out": 0}
    with staging(out, "process") as stage:
        for name in progress(names, desc="process", unit="sequence"):
            src = root / "lidar" / "sequences" / name
            meta = process_sequence(src, stage / "lidar" / "sequences" / name, gap, name)
            summary["points_out"] += sum(meta["points_per_scan"])
            summary["points_in"] += sum(r["points_in"] for r in meta["twin_of"]["scans"])
        split_cfg = root / "lidar" / "semantic-kitti.yaml"
        if split_cfg.is_file():
            shutil.copy2(split_cfg, stage / "lidar" / "semantic-kitti.yaml")   # its split, then new content
        write_dataset_label_config(stage / "lidar")
        if (root / "images").is_dir():
            _link_or_copy(root / "images", stage / "images")
        if (root / "manifest.json").is_file():
            shutil.copy2(root / "manifest.json", stage / "manifest.json")
        if labelled:
            from generator.jobs.boxes import write_sequence_openlabel

            for name in labelled:
                write_sequence_openlabel(spec, stage, name)   # the spec's threshold, as generate wrote them
        for top in sorted(stage.iterdir()):
            os.replace(top, out / top.name)
    return summary

