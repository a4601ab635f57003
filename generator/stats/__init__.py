"""Dataset statistics: one module per kind of data, each contributing a section to the report.

A statistics module ``generator.stats.<name>`` provides

* ``load(root: Path) -> data | None``: read what it needs from the dataset folder (None when
  the dataset has no such data; :class:`generator.errors.UserError` when it is malformed);
* ``section(data) -> generator.stats.report.Section``: the tables and figures;
* ``verify(data) -> list[str]`` (optional): recompute from the full files and list every
  disagreement with the fast path.

:data:`SECTIONS` lists the modules in report order. LiDAR points per class and 3D boxes per
class are meant to be added as sibling modules (``lidar``, ``boxes``) listed here.
"""

from __future__ import annotations

import importlib
from types import ModuleType

#: Statistics modules, in report order.
SECTIONS = ("images", "class_mix", "box_counts", "assets")


def section_modules() -> list[ModuleType]:
    """The statistics modules of :data:`SECTIONS`, imported."""
    return [importlib.import_module(f"generator.stats.{name}") for name in SECTIONS]
