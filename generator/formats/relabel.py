"""Relabel a SemanticKITTI-layout dataset into another label set (seed 000's unified 11 classes).

All mappings are data: native -> raw is ``generator/labels/classes.yaml`` (``semantickitti``
column), raw -> unified and the canonical unified -> raw are ``generator/labels/unified11.yaml``.
The lookups are :mod:`generator.labels.sets`; this module rewrites whole datasets.

:func:`convert_dataset` copies ``velodyne/*.bin``, ``poses.txt``, ``calib.txt`` and
``times.txt`` of each sequence, rewrites every ``.label`` with unified ids in the low 16
bits (instance ids in the high 16 bits kept), and writes ``OUT/unified11.yaml`` (the
unified label config in the layout of ``semantic-kitti.yaml``: labels, color_map (BGR),
content of the sequences converted, identity learning maps, 0 = unlabeled ignored, split)
and ``OUT/conversion.json``. ``split`` lists every sequence in OUT: the converted ones under
``--split`` if given, else under the split ``IN/semantic-kitti.yaml`` gives them, else
``valid`` (semantic-kitti-api's default); sequences already in OUT keep their split
(:func:`generator.formats.label_config.merge_split`).
Everything is staged in a temporary folder inside OUT and moved into place only once every
scan has converted, so a bad input leaves OUT as it was.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generator import __version__, safeload
from generator.atomic import staging, write_bytes, write_json, write_text
from generator.errors import UserError
from generator.formats import semantickitti as sk
from generator.formats.label_config import (
    SPLITS,
    count_raw_ids,
    format_label_config,
    merge_counts,
    merge_split,
    read_split,
)
from generator.labels import class_table
from generator.labels.sets import semantickitti_to_unified
from generator.progress import progress as progress_bar

log = logging.getLogger(__name__)

COPIED_FILES = ("poses.txt", "calib.txt", "times.txt")
SOURCE_CONFIG = "semantic-kitti.yaml"


# -- target label configs ----------------------------------------------------------------
def unified_label_config(counts: dict[int, int], split: dict[str, list[int]]) -> dict:
    """The unified set's label config as plain data (sections of ``semantic-kitti.yaml``).

    ``color_map`` (BGR) is the reference colour of each class's canonical raw id;
    ``learning_map`` is the identity with 0 (unlabeled) ignored; ``split`` as given
    (:func:`generator.formats.label_config.merge_split`).
    """
    table = class_table()
    names = table.unified_names
    total = sum(counts.values())
    return {
        "labels": dict(names),
        "color_map": {u: list(table.sk_colors_bgr[table.unified_to_sk_map[u]]) for u in names},
        "content": {u: (counts.get(u, 0) / total if total else 0.0) for u in names},
        "learning_map": {u: u for u in names},
        "learning_map_inv": {u: u for u in names},
        "learning_ignore": {u: u == 0 for u in names},
        "split": {part: sorted(int(s) for s in split.get(part, [])) for part in SPLITS},
    }


def format_unified_config(cfg: dict) -> str:
    """YAML text of :func:`unified_label_config`, laid out like the reference file."""
    body = format_label_config(cfg).split("\n", 2)[2]  # drop the SemanticKITTI header comment
    return ("# Unified 11-class label config (seed 000 Sec. IV.A) of a dataset converted by urbangen convert;\n"
            "# raw -> unified map: generator/labels/unified11.yaml; content from the written labels.\n" + body)


@dataclass(frozen=True)
class Target:
    """A label set a dataset can be converted into: per-scan relabelling and its config file."""

    relabel: Callable[[np.ndarray, str], np.ndarray]
    config_name: str
    config: Callable[[dict, list], dict]
    formatter: Callable[[dict], str]


#: Conversion targets by ``--labels`` name (label sets of :mod:`generator.labels.sets`).
TARGETS: dict[str, Target] = {
    "unified11": Target(semantickitti_to_unified, "unified11.yaml", unified_label_config, format_unified_config),
}


# -- datasets -------------------------------------------------------------------------------
def pick_sequences(root: Path, sequences: list[str] | None) -> list[str]:
    """The sequences to convert: all with labels, or the listed ones (each must exist with labels)."""
    present = sk.list_sequences(root)
    names = present if sequences is None else [sk.sequence_name(s) for s in sequences]
    for n in names:
        if n not in present:
            raise UserError(f"{root / 'sequences' / n}: sequence not found (present: {', '.join(present) or 'none'})")
        if not (root / "sequences" / n / "labels").is_dir():
            raise UserError(f"{root / 'sequences' / n / 'labels'}: missing; nothing to convert")
    if not names:
        raise UserError(f"{root / 'sequences'}: no sequences")
    return names


def convert_dataset(src: str | Path, dst: str | Path, labels: str = "unified11", sequences: list[str] | None = None,
                    progress: bool = True, split: str | None = None) -> dict:
    """Rewrite the labels of a SemanticKITTI-layout dataset into another label set.

    Parameters
    ----------
    src, dst : path-like
        Dataset roots (``src/sequences/NN``); ``dst`` may exist but must not hold the sequences written.
    labels : str
        A key of :data:`TARGETS`.
    sequences : list of str, optional
        Sequence numbers (default: every sequence with labels).
    split : {"train", "valid", "test"}, optional
        Split of the converted sequences in the written config (default: their split in
        ``src/semantic-kitti.yaml``, else ``valid``).

    Returns
    -------
    dict
        The summary written to ``dst/conversion.json``.
    """
    if labels not in TARGETS:
        raise UserError(f"--labels: unknown label set {labels!r}; known: {', '.join(TARGETS)}")
    if split is not None and split not in SPLITS:
        raise UserError(f"--split: must be one of {', '.join(SPLITS)}, got {split!r}")
    target = TARGETS[labels]
    src, dst = Path(src), Path(dst)
    if dst.exists() and not dst.is_dir():
        raise UserError(f"{dst}: exists and is not a folder")
    if os.path.realpath(dst) == os.path.realpath(src):
        raise UserError(f"{dst}: output must differ from the input dataset")
    names = pick_sequences(src, sequences)
    seqs = [sk.Sequence(src, n) for n in names]  # validates folders, poses/times lengths
    for seq in seqs:
        if len(seq) == 0:
            raise UserError(f"{seq.dir / 'velodyne'}: no scans; nothing to convert")
    for n in names:
        if (dst / "sequences" / n).exists():
            raise UserError(f"{dst / 'sequences' / n}: exists; remove it or choose another output folder")
    counts: dict[int, int] = {}
    with staging(dst, "convert") as stage:
        bar = progress_bar(total=sum(len(s) for s in seqs), desc=f"convert -> {labels}", unit="scan", enabled=progress)
        with bar:
            for seq in seqs:
                out = stage / "sequences" / seq.dir.name
                (out / "velodyne").mkdir(parents=True)
                for f in COPIED_FILES:  # already parsed and checked by sk.Sequence; copied as read
                    if os.path.lexists(seq.dir / f):
                        write_bytes(out / f, safeload.read_bytes(seq.dir / f, max_bytes=safeload.MAX_TABLE_BYTES))
                for i in seq.frames:
                    pts, sem, inst = seq.read_labelled(i)  # whole 16-byte finite points, one label each
                    new = target.relabel(sem, str(seq.label_path(i)))
                    sk.write_labels(out / "labels" / seq.label_path(i).name, new, inst)
                    write_bytes(out / "velodyne" / seq.scan_path(i).name, pts.astype("<f4").tobytes())
                    counts = merge_counts(counts, count_raw_ids(new))
                    bar.update()
        (dst / "sequences").mkdir(exist_ok=True)
        for n in names:
            (stage / "sequences" / n).rename(dst / "sequences" / n)
    source = {int(s): part for part, seqs in read_split(src / SOURCE_CONFIG).items() for s in seqs}
    assigned = {int(n): split or source.get(int(n)) for n in names}
    parts = merge_split([int(n) for n in sk.list_sequences(dst)], {k: v for k, v in assigned.items() if v},
                        read_split(dst / target.config_name))
    cfg = target.config(counts, parts)  # content: the sequences of this run; split: every sequence in dst
    write_text(dst / target.config_name, target.formatter(cfg))
    summary = {"generator": f"urbangen {__version__} convert", "source": str(src), "labels": labels,
               "mapping": "native -> SemanticKITTI raw (generator/labels/classes.yaml) -> unified "
                          "(generator/labels/unified11.yaml from_semantickitti); instance ids kept",
               "sequences": names, "scans": int(sum(len(s) for s in seqs)),
               "label_counts": {str(k): v for k, v in sorted(counts.items())}, "config": target.config_name}
    write_json(dst / "conversion.json", summary)
    return summary
