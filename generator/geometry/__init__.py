"""Geometry: the ground floor both assets and the scene stand on.

Labelled triangle meshes (:mod:`.mesh`), the primitives assets are built from
(:mod:`.primitives`), rigid transforms (:mod:`.transforms`) and the convex-hull label
proxies (:mod:`.proxy`). Depends only on the data tables (``generator.labels``,
``generator.materials``); ``assets_procedural``, the scene, the layout and the Blender
edge build on it, never the reverse.
"""

from generator.geometry.mesh import Mesh, empty, face_normals, merge, on_ground
from generator.geometry.primitives import (
                                           box,
                                           convex_hull,
                                           cylinder,
                                           disc,
                                           icosphere,
                                           loft,
                                           polygon,
                                           prism,
                                           quad,
                                           quads,
                                           rect,
                                           resolve_ids,
                                           slab,
                                           triangulate,
                                           tube,
)
from generator.geometry.transforms import apply, cross, invert, mount, pose, unit

__all__ = ["Mesh", "apply", "box", "convex_hull", "cross", "cylinder", "disc", "empty", "face_normals", "icosphere",
           "invert", "loft", "merge", "mount", "on_ground", "polygon", "pose", "prism", "quad", "quads", "rect",
           "resolve_ids", "slab", "triangulate", "tube", "unit"]
