"""The dataset's label config YAML, in the format of SemanticKITTI's ``semantic-kitti.yaml``.

Sections ``labels``, ``color_map`` (BGR), ``learning_map``, ``learning_map_inv`` and
``learning_ignore`` are the reference ones (``generator/labels/semantic-kitti.yaml``), so
SemanticKITTI tools read an urbangen dataset unchanged. They include the moving-* ids
252-259 that points on moving actors carry (:func:`generator.labels.sets.semantickitti_labels`),
with the reference ``learning_map`` (moving-car -> car ...), so semantic-kitti-api's remap
LUTs cover them. ``content`` (fraction of points per raw id, every reference id listed, moving
ones included) is computed from the labels actually written.

``split`` lists every sequence present in the dataset, each under exactly one of
``train``, ``valid``, ``test`` (:func:`merge_split`): the split a command was asked for
(``--split``), else the one the config on disk already gives it, else :data:`DEFAULT_SPLIT`
= ``valid``, the split semantic-kitti-api's ``evaluate_semantics.py`` and
``evaluate_panoptic.py`` evaluate when run without ``-s``; sequences no longer on disk are
dropped (the api would look for their folders).
"""

from __future__ import annotations

import logging
import os
from pathlib import Path

import numpy as np

from generator import safeload
from generator.atomic import write_text
from generator.errors import SpecError, UserError
from generator.formats.semantickitti import MAX_SEQUENCE
from generator.labels import class_table

log = logging.getLogger(__name__)

#: The split names of the reference config, in its order.
SPLITS = ("train", "valid", "test")
#: Split of a sequence nobody assigned: what semantic-kitti-api evaluates by default (``-s valid``).
DEFAULT_SPLIT = "valid"
#: Values a label config may hold (the reference has ~700; content and maps of 65536 ids at most).
MAX_CONFIG_NODES = 1_000_000


def count_raw_ids(semantic: np.ndarray) -> dict[int, int]:
    """Points per SemanticKITTI raw id in (n,) uint16 ``semantic``."""
    ids, counts = np.unique(np.asarray(semantic), return_counts=True)
    return {int(i): int(c) for i, c in zip(ids, counts, strict=False)}


def merge_counts(*counts: dict[int, int]) -> dict[int, int]:
    """Sum several ``count_raw_ids`` results."""
    out: dict[int, int] = {}
    for c in counts:
        for k, v in c.items():
            out[int(k)] = out.get(int(k), 0) + int(v)
    return out


def read_split(path: str | Path) -> dict[str, list[int]]:
    """The ``split`` section of a label config on disk (empty when the file is missing or unreadable).

    Read through :mod:`generator.safeload` (size limit, strict YAML, no aliases beyond a
    small budget); a config that cannot be read or whose split is malformed is logged as
    one line (never quoting the file) and treated as having no split.
    """
    path = Path(path)
    if not os.path.lexists(path):
        return {}
    try:
        doc = safeload.load_yaml(path, string_keys=False, max_nodes=MAX_CONFIG_NODES)
        split = (doc.get("split") if isinstance(doc, dict) else None) or {}
        if not isinstance(split, dict):
            raise SpecError(str(path), "split", "must be a mapping of train, valid, test to sequence lists")
        out = {}
        for part in SPLITS:
            seqs = split.get(part) or []
            if not isinstance(seqs, list) or not all(isinstance(s, int) and not isinstance(s, bool)
                                                     and 0 <= s <= MAX_SEQUENCE for s in seqs):
                raise SpecError(str(path), f"split.{part}", f"must be a list of sequence numbers 0..{MAX_SEQUENCE}")
            out[part] = list(seqs)
        return out
    except UserError as e:
        log.warning("%s; sequences get their --split or %s", e, DEFAULT_SPLIT)
        return {}


def merge_split(sequences: list[int], assigned: dict[int, str] | None = None,
                previous: dict[str, list[int]] | None = None, default: str = DEFAULT_SPLIT) -> dict[str, list[int]]:
    """Each of ``sequences`` under exactly one split.

    Parameters
    ----------
    sequences : list of int
        The sequences present in the dataset (only these are listed).
    assigned : dict, optional
        Sequence -> split for the sequences a command was asked to place (``--split``).
    previous : dict, optional
        The ``split`` section on disk (:func:`read_split`): kept for the other sequences.
    default : str
        Split of sequences neither assigned nor listed before.

    Returns
    -------
    dict
        ``{"train": [...], "valid": [...], "test": [...]}``, sorted sequence numbers.
    """
    assigned = {int(k): v for k, v in (assigned or {}).items()}
    before = {int(s): part for part in SPLITS for s in (previous or {}).get(part, [])}
    out: dict[str, list[int]] = {part: [] for part in SPLITS}
    for s in sorted({int(s) for s in sequences}):
        part = assigned.get(s) or before.get(s) or default
        if part not in SPLITS:
            raise ValueError(f"split must be one of {', '.join(SPLITS)}, got {part!r}")
        out[part].append(s)
    return out


def label_config(counts: dict[int, int], split: dict[str, list[int]]) -> dict:
    """The config as plain data: reference maps plus ``content`` from ``counts`` and ``split`` (:func:`merge_split`).

    Raises
    ------
    ValueError
        If ``counts`` holds a raw id the reference labels do not know.
    """
    ref = class_table().sk_config
    labels = {int(k): v for k, v in ref["labels"].items()}
    unknown = sorted(set(counts) - set(labels))
    if unknown:
        raise ValueError(f"raw ids {unknown} are not SemanticKITTI labels")
    total = sum(counts.values())
    content = {k: (counts.get(k, 0) / total if total else 0.0) for k in labels}
    return {
        "labels": labels,
        "color_map": {int(k): list(v) for k, v in ref["color_map"].items()},
        "content": content,
        "learning_map": {int(k): int(v) for k, v in ref["learning_map"].items()},
        "learning_map_inv": {int(k): int(v) for k, v in ref["learning_map_inv"].items()},
        "learning_ignore": {int(k): bool(v) for k, v in ref["learning_ignore"].items()},
        "split": {part: sorted(int(s) for s in split.get(part, [])) for part in SPLITS},
    }


def format_label_config(cfg: dict) -> str:
    """YAML text laid out like the reference file (one ``id: value`` per line, colours as ``[b, g, r]``)."""
    out = ["# SemanticKITTI label config of an urbangen dataset (maps from the reference",
           "# semantic-kitti.yaml; content computed from the written labels)."]
    comments = {"color_map": " # bgr", "content": " # as a ratio with the total number of points",
                "learning_map_inv": " # inverse of previous map", "learning_ignore": " # Ignore classes",
                "split": " # sequence numbers"}
    for section in ("labels", "color_map", "content", "learning_map", "learning_map_inv", "learning_ignore"):
        out.append(f"{section}:{comments.get(section, '')}")
        for k, v in cfg[section].items():
            if section == "labels":
                val = f'"{v}"'
            elif section == "color_map":
                val = "[" + ", ".join(str(int(c)) for c in v) + "]"
            elif section == "content":
                val = repr(float(v))
            elif section == "learning_ignore":
                val = "True" if v else "False"
            else:
                val = str(v)
            out.append(f"  {k}: {val}")
    out.append(f"split:{comments['split']}")
    for part in SPLITS:
        seqs = cfg["split"][part]
        out.append(f"  {part}:" + ("" if seqs else " []"))
        out.extend(f"    - {s}" for s in seqs)
    return "\n".join(out) + "\n"


def write_label_config(path: str | Path, counts: dict[int, int], split: dict[str, list[int]]) -> dict:
    """Write the config atomically and return it."""
    cfg = label_config(counts, split)
    write_text(path, format_label_config(cfg))
    return cfg
