"""Asset variety: distinct prototype meshes per kind over a dataset's LiDAR sequences (issue 29).

Each sequence's ``lidar_meta.json`` records the census of its world (``prototypes``: per kind,
the objects and the hash names of their meshes, :mod:`generator.world.census`): the static town
and the traffic, whether or not the sensor saw them. The union over every sequence is the number of
different shapes a detector trained on the dataset meets per kind (sequences of the same town
share theirs; re-drawn towns bring new ones, ``assets.redraw_every_towns``).

A statistics module (``load`` / ``section``, see :mod:`generator.stats`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from generator.errors import UserError
from generator.imaging import meta_fields as md
from generator.stats.report import Section, Table

#: kinds listed first (the ones issue 29 counts), then the rest by distinct meshes
FIRST = ("car", "person", "truck", "bus", "bicyclist", "motorcyclist", "tree")


@dataclass
class AssetData:
    """Per kind: the distinct mesh names, the objects summed over sequences; the sequences read."""

    meshes: dict[str, set[str]]
    objects: dict[str, int]
    sequences: list[str]


def load(root: Path) -> AssetData | None:
    """The census of every ``lidar/sequences/NN/lidar_meta.json`` of ``root``; None when none has one."""
    base = Path(root) / "lidar" / "sequences"
    meshes: dict[str, set[str]] = {}
    objects: dict[str, int] = {}
    seqs = []
    for meta_path in sorted(base.glob("[0-9][0-9]/lidar_meta.json")) if base.is_dir() else []:
        census = md.load_metadata(meta_path).get("prototypes")
        if census is None:
            continue
        if not isinstance(census, dict):
            raise UserError(f"{meta_path}: prototypes: must be an object of kinds")
        for kind, entry in census.items():
            ok = isinstance(entry, dict) and isinstance(entry.get("meshes"), list) and \
                type(entry.get("objects")) is int
            if not ok:
                raise UserError(f"{meta_path}: prototypes.{str(kind)[:40]}: must be {{objects: int, meshes: list}}")
            meshes.setdefault(kind, set()).update(str(m) for m in entry["meshes"])
            objects[kind] = objects.get(kind, 0) + entry["objects"]
        seqs.append(meta_path.parent.name)
    return AssetData(meshes, objects, seqs) if seqs else None


def section(data: AssetData) -> Section:
    """Distinct meshes per kind."""
    kinds = [k for k in FIRST if k in data.meshes]
    kinds += sorted((k for k in data.meshes if k not in FIRST), key=lambda k: (-len(data.meshes[k]), k))
    rows = [[k, len(data.meshes[k]), data.objects[k]] for k in kinds]
    table = Table("assets_distinct_meshes", "Distinct prototype meshes per kind",
                  ["Kind", "Distinct meshes", "Objects (summed over sequences)"],
                  ["kind", "distinct_meshes", "objects"], rows,
                  [f"From the prototype census of {len(data.sequences)} LiDAR sequence(s) (lidar_meta.json "
                   "prototypes): every thing of the town and its traffic, seen or not. A mesh is named by a hash "
                   "of its vertices and faces, so a kind's count is the number of different shapes of it."])
    head = ", ".join(f"{k} {len(data.meshes[k])}" for k in kinds[:4])
    return Section("Asset variety", [f"distinct meshes: {head} ({len(data.sequences)} sequences)"], [table])
