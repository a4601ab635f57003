"""The surface material table (``materials.yaml``), shared by assets, Blender and LiDAR."""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generator.safeload import load_package_yaml


def srgb_to_linear(c: np.ndarray) -> np.ndarray:
    """(..., 3) float linear RGB of (..., 3) sRGB values in [0, 255] (IEC 61966-2-1)."""
    s = np.asarray(c, float) / 255.0
    return np.where(s <= 0.04045, s / 12.92, ((s + 0.055) / 1.055) ** 2.4)


@dataclass(frozen=True)
class MaterialInfo:
    """One row of the material table."""

    id: int
    name: str
    reflectivity: float
    retro: bool
    color: tuple[int, int, int]
    emissive: str | None
    transmittance: float = 0.0
    behind: str | None = None


class MaterialTable:
    """Material rows with name lookup and per-id arrays."""

    def __init__(self, rows: list[MaterialInfo], cabins: tuple[str, ...] = (), interiors: tuple[str, ...] = ()):
        if [r.id for r in rows] != list(range(len(rows))):
            raise ValueError("materials.yaml: ids must be 0..N-1 in order")
        for r in rows:
            if r.behind not in (None, "room") or (r.behind and r.transmittance <= 0):
                raise ValueError(f"materials.yaml: {r.name}.behind must be 'room' on a glass material "
                                 f"(transmittance > 0), got {r.behind!r}")
        self.rows = rows
        #: classes whose glass closes an unmodelled cabin (``cabins`` in materials.yaml)
        self.cabins = tuple(cabins)
        #: classes whose cabin is modelled behind their glass (``interiors`` in materials.yaml)
        self.interiors = tuple(interiors)
        if set(self.cabins) & set(self.interiors):
            raise ValueError(f"materials.yaml: classes both in cabins and interiors: "
                             f"{sorted(set(self.cabins) & set(self.interiors))}")
        self.names = [r.name for r in rows]
        self._by_name = {r.name: r for r in rows}

    def __len__(self) -> int:
        return len(self.rows)

    def __getitem__(self, key: int | str) -> MaterialInfo:
        return self._by_name[key] if isinstance(key, str) else self.rows[key]

    def id(self, name: str) -> int:
        """Material id of ``name``."""
        try:
            return self._by_name[name].id
        except KeyError:
            raise KeyError(f"unknown material {name!r}; known: {', '.join(self.names)}") from None

    @functools.cached_property
    def reflectivity(self) -> np.ndarray:
        """(n_materials,) float32 diffuse reflectivity at 905 nm."""
        return np.array([r.reflectivity for r in self.rows], np.float32)

    @functools.cached_property
    def retro(self) -> np.ndarray:
        """(n_materials,) bool: retroreflective surfaces."""
        return np.array([r.retro for r in self.rows], bool)

    @functools.cached_property
    def transmittance(self) -> np.ndarray:
        """(n_materials,) float32 share of a 905 nm beam a pane lets through, one way (0: opaque)."""
        return np.array([r.transmittance for r in self.rows], np.float32)

    @functools.cached_property
    def room_behind(self) -> np.ndarray:
        """(n_materials,) bool: the pane is the window of an unmodelled room (``behind: room``)."""
        return np.array([r.behind == "room" for r in self.rows], bool)

    @functools.cached_property
    def colors(self) -> np.ndarray:
        """(n_materials, 3) uint8 preview colour."""
        return np.array([r.color for r in self.rows], np.uint8)


@functools.cache
def material_table() -> MaterialTable:
    """The package's material table (read once)."""
    with open(Path(__file__).with_name("materials.yaml"), encoding="utf-8") as f:
        doc = load_package_yaml(f)
    raw = doc["materials"]
    return MaterialTable(
        [
            MaterialInfo(int(r["id"]), str(r["name"]), float(r["reflectivity"]), bool(r["retro"]),
                         tuple(int(c) for c in r["color"]), r["emissive"],
                         float(r.get("transmittance", 0.0)), r.get("behind"))
            for r in raw
        ],
        tuple(str(c) for c in doc.get("cabins", ())),
        tuple(str(c) for c in doc.get("interiors", ())),
    )
