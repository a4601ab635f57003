"""Procedural town layout (pure numpy): streets, lots, placements, routes and frames.

``build_scene(spec) -> SceneModel`` (from :mod:`generator.layout.assemble`) builds the whole town.
"""

from generator.layout.assemble import build_scene

__all__ = ["build_scene"]
