"""The dataset's label config YAML, in the format of SemanticKITTI's ``semantic-kitti.yaml``.

Sections ``labels``, ``color_map`` (BGR), ``learning_map``, ``learning_map_inv`` and
``learning_ignore`` are the reference ones (``generator/labels/semantic-kitti.yaml``), so
SemanticKITTI tools read an urbangen dataset unchanged. ``content`` (fraction of points
per raw id) is computed from the labels actually written. ``split`` lists every sequence
of the dataset under ``train`` (urbangen does not choose a split; edit it for yours).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from generator.atomic import write_text
from generator.labels import class_table


def count_raw_ids(semantic: np.ndarray) -> dict[int, int]:
    """Points per SemanticKITTI raw id in (n,) uint16 ``semantic``."""
    ids, counts = np.unique(np.asarray(semantic), return_counts=True)
    return {int(i): int(c) for i, c in zip(ids, counts)}


def merge_counts(*counts: dict[int, int]) -> dict[int, int]:
    """Sum several ``count_raw_ids`` results."""
    out: dict[int, int] = {}
    for c in counts:
        for k, v in c.items():
            out[int(k)] = out.get(int(k), 0) + int(v)
    return out


def label_config(counts: dict[int, int], sequences: list[int]) -> dict:
    """The config as plain data: reference maps plus ``content`` from ``counts`` and ``split``.

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
        "split": {"train": sorted(int(s) for s in sequences), "valid": [], "test": []},
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
    for part in ("train", "valid", "test"):
        seqs = cfg["split"][part]
        out.append(f"  {part}:" + ("" if seqs else " []"))
        out.extend(f"    - {s}" for s in seqs)
    return "\n".join(out) + "\n"


def write_label_config(path: str | Path, counts: dict[int, int], sequences: list[int]) -> dict:
    """Write the config atomically and return it."""
    cfg = label_config(counts, sequences)
    write_text(path, format_label_config(cfg))
    return cfg
