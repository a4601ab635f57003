"""The one guarded entry to bpy.

Importing this module imports ``bpy`` with an actionable message when Blender is not
installed, after dropping the ``bpy/<version>/scripts`` entries a parent process may
have left on ``sys.path`` (a spawned worker inherits its parent's path, and those
entries make a second ``import bpy`` in the child fail).
"""

from __future__ import annotations

import sys

from generator.errors import UserError


def _clean_sys_path() -> None:
    sys.path[:] = [p for p in sys.path if "/scripts" not in p.replace("\\", "/") or "bpy/" not in p.replace("\\", "/")]


if "bpy" not in sys.modules:
    _clean_sys_path()
try:
    import bpy  # noqa: E402
except ImportError as e:  # pragma: no cover - depends on the installation
    raise UserError(
        f"Blender as a Python module (bpy) is needed for rendering but cannot be imported ({e}). "
        "Install it with: pip install 'bpy==5.0.1' (Python 3.11 and numpy<2 only)."
    ) from None
import mathutils  # noqa: E402  (only importable once bpy is)

__all__ = ["bpy", "mathutils"]
