"""Kept only so that tests written against the old name still import: the one kit is
:mod:`kits.scene_kit` (import ``scene_of`` and ``straight_path`` from there)."""

from kits.scene_kit import scene_of, straight_path

__all__ = ["scene_of", "straight_path"]
