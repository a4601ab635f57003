"""The native class table (``classes.yaml``) and the label sets derived from it.

Every other label set is a lookup array built from the one table:

* SemanticKITTI raw ids (``to_semantickitti``; ``to_semantickitti_moving`` for points on
  moving actors, the reference's moving-* ids 252-259), with the reference label config
  ``semantic-kitti.yaml`` for names and colours;
* the unified 11 classes of seed 000 (``unified11.yaml`` maps SemanticKITTI raw ids,
  so native -> unified is the composition native -> raw -> unified);
* Cityscapes ids and colours; seed-003 class names; the mask-proxy policy.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generator.safeload import load_package_yaml

DATA_DIR = Path(__file__).resolve().parent
#: SemanticKITTI raw id written for classes that never return a LiDAR point (sky).
NO_RETURN = 0


@dataclass(frozen=True)
class ClassInfo:
    """One row of the native class table."""

    id: int
    name: str
    seed003: str | None
    semantickitti: int | None
    cityscapes: int
    color: tuple[int, int, int]
    proxy: str
    thing: bool


def _load_yaml(name: str) -> dict:
    with open(DATA_DIR / name, encoding="utf-8") as f:
        return load_package_yaml(f)


class ClassTable:
    """The native classes and every mapping derived from them.

    Lookup arrays are indexed by native id and have one entry per class.
    """

    def __init__(self, rows: list[ClassInfo], sk_config: dict, unified: dict, wet_ground: list[int] = (),
                 moving: dict[str, int] | None = None):
        ids = [r.id for r in rows]
        if ids != list(range(len(rows))):
            raise ValueError(f"classes.yaml: ids must be 0..{len(rows) - 1} in order, got {ids}")
        names = [r.name for r in rows]
        if len(set(names)) != len(names):
            raise ValueError("classes.yaml: duplicate class names")
        self.rows = rows
        self.names: list[str] = names
        self._by_name = {r.name: r for r in rows}
        self.sk_labels: dict[int, str] = {int(k): v for k, v in sk_config["labels"].items()}
        self.sk_colors_bgr: dict[int, list[int]] = {int(k): v for k, v in sk_config["color_map"].items()}
        self.sk_config = sk_config
        self.unified_names: dict[int, str] = {int(k): v for k, v in unified["classes"].items()}
        self.sk_to_unified_map: dict[int, int] = {int(k): int(v) for k, v in unified["from_semantickitti"].items()}
        self.unified_to_sk_map: dict[int, int] = {int(k): int(v) for k, v in unified["to_semantickitti"].items()}
        #: SemanticKITTI raw ids of paved ground (``wet_ground_semantickitti`` in ``classes.yaml``)
        self.wet_ground_raw_ids: tuple[int, ...] = tuple(int(i) for i in wet_ground)
        for raw in self.wet_ground_raw_ids:
            if raw not in self.sk_labels:
                raise ValueError(f"classes.yaml: wet_ground_semantickitti: unknown SemanticKITTI id {raw}")
        for r in rows:
            if r.semantickitti is not None and r.semantickitti not in self.sk_labels:
                raise ValueError(f"classes.yaml: {r.name}: unknown SemanticKITTI id {r.semantickitti}")
            if r.proxy not in ("none", "hull"):
                raise ValueError(f"classes.yaml: {r.name}: proxy must be 'none' or 'hull', got {r.proxy!r}")
        #: native class name -> SemanticKITTI moving-* raw id (``semantickitti_moving`` in ``classes.yaml``)
        self.moving_raw_ids: dict[str, int] = {str(k): int(v) for k, v in (moving or {}).items()}
        self._check_moving(sk_config)

    def _check_moving(self, sk_config: dict) -> None:
        learning = {int(k): int(v) for k, v in sk_config["learning_map"].items()}
        for name, raw in self.moving_raw_ids.items():
            where = f"classes.yaml: semantickitti_moving: {name}"
            if name not in self._by_name:
                raise ValueError(f"{where}: unknown native class")
            static = self._by_name[name].semantickitti
            if raw not in self.sk_labels or not self.sk_labels[raw].startswith("moving-"):
                raise ValueError(f"{where}: {raw} is not a SemanticKITTI moving-* id")
            if static is None or learning.get(raw) != learning.get(static) \
                    or self.sk_to_unified_map.get(raw) != self.sk_to_unified_map.get(static):
                raise ValueError(f"{where}: {raw} must map to the learning and unified class of {static}")

    # -- single lookups ---------------------------------------------------------------
    def __len__(self) -> int:
        return len(self.rows)

    def __getitem__(self, key: int | str) -> ClassInfo:
        return self._by_name[key] if isinstance(key, str) else self.rows[key]

    def id(self, name: str) -> int:
        """Native id of class ``name`` (KeyError names the class if unknown)."""
        try:
            return self._by_name[name].id
        except KeyError:
            raise KeyError(f"unknown class {name!r}; known: {', '.join(self.names)}") from None

    # -- lookup arrays (index with native ids) -------------------------------------------
    @functools.cached_property
    def to_semantickitti(self) -> np.ndarray:
        """(n_classes,) uint16: SemanticKITTI raw id per native id (no-return classes -> 0)."""
        return np.array([NO_RETURN if r.semantickitti is None else r.semantickitti for r in self.rows], np.uint16)

    @functools.cached_property
    def to_semantickitti_moving(self) -> np.ndarray:
        """(n_classes,) uint16: SemanticKITTI raw id per native id for a point on a MOVING actor.

        The moving-* id (252-259) where the class has one, else the static id (``to_semantickitti``).
        """
        out = self.to_semantickitti.copy()
        for name, raw in self.moving_raw_ids.items():
            out[self._by_name[name].id] = raw
        return out

    @functools.cached_property
    def sk_to_unified(self) -> np.ndarray:
        """(max_raw_id + 1,) uint8: unified-11 id per SemanticKITTI raw id (unknown raw ids -> 0)."""
        lut = np.zeros(max(self.sk_labels) + 1, np.uint8)
        for raw, uni in self.sk_to_unified_map.items():
            lut[raw] = uni
        return lut

    @functools.cached_property
    def to_unified(self) -> np.ndarray:
        """(n_classes,) uint8: unified-11 id per native id (composition native -> raw -> unified)."""
        return self.sk_to_unified[self.to_semantickitti]

    @functools.cached_property
    def to_cityscapes(self) -> np.ndarray:
        """(n_classes,) uint8: Cityscapes label id per native id."""
        return np.array([r.cityscapes for r in self.rows], np.uint8)

    @functools.cached_property
    def colors(self) -> np.ndarray:
        """(n_classes, 3) uint8 RGB preview colour per native id."""
        return np.array([r.color for r in self.rows], np.uint8)

    @functools.cached_property
    def hull_classes(self) -> np.ndarray:
        """(n_classes,) bool: classes whose objects get a convex-hull label proxy."""
        return np.array([r.proxy == "hull" for r in self.rows], bool)

    @functools.cached_property
    def lidar_returns(self) -> np.ndarray:
        """(n_classes,) bool: classes with geometry a LiDAR can hit (False for sky)."""
        return np.array([r.semantickitti is not None for r in self.rows], bool)

    def seed003_names(self) -> list[str]:
        """The distinct seed-003 class names, in table order (Table I rows)."""
        out: list[str] = []
        for r in self.rows:
            if r.seed003 is not None and r.seed003 not in out:
                out.append(r.seed003)
        return out

    def to_seed003(self) -> list[str | None]:
        """Seed-003 name per native id (None where seed 003 had no such class)."""
        return [r.seed003 for r in self.rows]

    # -- canonical inverses (used to round-trip) -------------------------------------------
    def from_semantickitti(self, raw: int) -> int:
        """Canonical native id for a SemanticKITTI raw id (first native class mapping to it).

        A moving-* id gives the first native class whose moving id it is (252 -> car).

        Raises
        ------
        KeyError
            If no native class maps to ``raw``.
        """
        hits = np.flatnonzero(self.to_semantickitti == raw)
        if raw == NO_RETURN:
            return 0
        if hits.size == 0:
            hits = np.flatnonzero((self.to_semantickitti_moving == raw) & (self.to_semantickitti != raw))
        if hits.size == 0:
            raise KeyError(f"no native class maps to SemanticKITTI id {raw}")
        return int(hits[0])

    def sk_color_rgb(self, raw: int) -> tuple[int, int, int]:
        """RGB colour of SemanticKITTI raw id ``raw`` (the config stores BGR)."""
        b, g, r = self.sk_colors_bgr.get(raw, [0, 0, 0])
        return (r, g, b)


@functools.cache
def class_table() -> ClassTable:
    """The package's class table (read once from ``classes.yaml``)."""
    doc = _load_yaml("classes.yaml")
    raw = doc["classes"]
    rows = [
        ClassInfo(
            id=int(r["id"]), name=str(r["name"]), seed003=r["seed003"], semantickitti=r["semantickitti"],
            cityscapes=int(r["cityscapes"]), color=tuple(int(c) for c in r["color"]), proxy=str(r["proxy"]),
            thing=bool(r["thing"]),
        )
        for r in raw
    ]
    return ClassTable(rows, _load_yaml("semantic-kitti.yaml"), _load_yaml("unified11.yaml"),
                      doc.get("wet_ground_semantickitti", ()), doc.get("semantickitti_moving", {}))
