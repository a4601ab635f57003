"""Convex-hull label proxies for objects with holes (fences, foliage, hedges).

The label pass draws the hull instead of the object, so a fence or a crown fills its mask
as a person would outline it; LiDAR still casts against the real, gappy geometry. Which
classes get a hull is data: the ``proxy`` column of ``generator/labels/classes.yaml``.
"""

from __future__ import annotations

import numpy as np

from generator.geometry.mesh import Mesh, merge
from generator.geometry.primitives import convex_hull
from generator.labels import class_table


def label_proxy(mesh: Mesh, inflate: float = 0.02) -> Mesh | None:
    """The hull proxy of ``mesh``: one convex hull per hull-policy class it contains, merged.

    Parameters
    ----------
    mesh : Mesh
        An asset in its local frame.
    inflate : float
        Metres each hull is pushed outward so it strictly contains its class's vertices.

    Returns
    -------
    Mesh or None
        Faces labelled with the class they stand for (material ``default``); ``None`` when
        no face of ``mesh`` has a hull-policy class (a car, a building). A tree's proxy is
        the hull of its crown only: the trunk keeps its real geometry.
    """
    hull_classes = class_table().hull_classes
    present = [int(c) for c in np.unique(mesh.face_class) if hull_classes[c]]
    if not present:
        return None
    return merge([convex_hull(mesh.select(mesh.face_class == c), c, inflate) for c in present])
