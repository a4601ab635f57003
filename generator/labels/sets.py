"""Label sets: every label set is a view of the one class table.

=============== ===================================================== ===================
name            classes (id 0 = unlabeled, ignored in evaluation)      from
=============== ===================================================== ===================
native          the native classes of ``classes.yaml``                  native id
semantickitti   SemanticKITTI's 19 learning classes + 0                 raw id (learning_map)
unified11       seed 000's 11 classes (``unified11.yaml``)              raw id
=============== ===================================================== ===================

Each set maps native ids (:attr:`LabelSet.from_native`) and, where SemanticKITTI raw
ids determine it, raw ids (:attr:`LabelSet.from_raw`). The raw-id mappings between the
datasets (:func:`native_to_semantickitti`, :func:`semantickitti_labels` with the moving-*
ids, :func:`semantickitti_to_unified`, :func:`unified_to_semantickitti`) live here too, so no
other module rebuilds them. The moving-* raw ids 252-259 map to the learning and unified
classes of their static ids (``learning_map``, ``unified11.yaml``), so every raw-id lookup
above reads them.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from generator.errors import UserError
from generator.labels.registry import class_table

#: Label set names, in the order commands list them.
LABEL_SET_NAMES = ("unified11", "semantickitti", "native")
RAW_IDS = 1 << 16  # every uint16 raw id


@dataclass(frozen=True)
class LabelSet:
    """One label set.

    Attributes
    ----------
    name : str
    names : tuple of str
        Class name of each id ``0 .. len(names) - 1``.
    from_native : (n_native,) int64
        Id in this set of each native class id.
    from_raw : (65536,) int64 or None
        Id in this set of each SemanticKITTI raw id (unknown raw ids -> 0); ``None`` when raw
        ids cannot tell the classes apart (the native set: read native side files instead).
    """

    name: str
    names: tuple[str, ...]
    from_native: np.ndarray
    from_raw: np.ndarray | None


def _lut(mapping: dict[int, int], size: int = RAW_IDS) -> np.ndarray:
    lut = np.zeros(size, np.int64)
    for k, v in mapping.items():
        lut[int(k)] = int(v)
    return lut


@functools.cache
def label_sets() -> dict[str, LabelSet]:
    """The label sets by name (built once from the class table)."""
    t = class_table()
    cfg = t.sk_config
    learning = _lut({int(k): int(v) for k, v in cfg["learning_map"].items()})
    learn_names = tuple(
        t.sk_labels[int(cfg["learning_map_inv"][i])] for i in sorted(int(k) for k in cfg["learning_map_inv"])
    )
    return {
        "unified11": LabelSet("unified11", tuple(t.unified_names[i] for i in sorted(t.unified_names)),
                              t.to_unified.astype(np.int64), _lut(t.sk_to_unified_map)),
        "semantickitti": LabelSet("semantickitti", learn_names, learning[t.to_semantickitti], learning),
        "native": LabelSet("native", tuple(t.names), np.arange(len(t), dtype=np.int64), None),
    }


def native_to_semantickitti(native: np.ndarray) -> np.ndarray:
    """(n,) uint16 SemanticKITTI raw ids of (n,) native class ids."""
    return class_table().to_semantickitti[np.asarray(native)]


def semantickitti_labels(native: np.ndarray, moving: np.ndarray | bool = False) -> np.ndarray:
    """(n,) uint16 SemanticKITTI raw ids of points: moving-* ids (252-259) where ``moving``.

    Parameters
    ----------
    native : (n,) integer
        Native class ids (``points["class"]``).
    moving : (n,) bool or uint8, or bool
        Whether each point lies on an actor moving faster than
        :data:`generator.world.actors.MOVING_THRESHOLD_MPS` at its firing time (``points["moving"]``).
        Classes without a moving id (stuff, a bicycle without its rider) keep their static id.
    """
    t = class_table()
    native = np.asarray(native)
    return np.where(np.asarray(moving, bool), t.to_semantickitti_moving[native], t.to_semantickitti[native])


def semantickitti_to_unified(raw: np.ndarray, source: str = "labels") -> np.ndarray:
    """(n,) uint16 unified-11 ids of (n,) SemanticKITTI raw ids.

    Raises
    ------
    UserError
        If a raw id is not in the reference label set (e.g. labels that are already unified).
    """
    table = class_table()
    raw = np.asarray(raw)
    unknown = [int(i) for i in np.unique(raw) if int(i) not in table.sk_labels]
    if unknown:
        raise UserError(f"{source}: raw ids {unknown[:8]} are not SemanticKITTI labels (already converted?)")
    return table.sk_to_unified[raw].astype(np.uint16)


def unified_to_semantickitti(unified: np.ndarray) -> np.ndarray:
    """(n,) uint16 canonical SemanticKITTI raw id of each unified-11 id (``unified11.yaml`` ``to_semantickitti``)."""
    m = class_table().unified_to_sk_map
    lut = np.zeros(max(m) + 1, np.uint16)
    for u, r in m.items():
        lut[u] = r
    return lut[np.asarray(unified)]
