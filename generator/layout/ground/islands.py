"""The island of a roundabout (its give-way lines: :func:`generator.layout.ground.markings.stop_marks`).

The island (:meth:`generator.layout.network.grid.Grid.islands`), class ``other_ground`` (the class
table's traffic islands and medians): a mountable apron ``APRON_H_M`` high out to ``island_r``
and, inside it, a kerbed centre raised to curb height out to ``core_r``, with a grass top (class
``terrain``) set back by a kerb band when it is large enough (:attr:`Ring.grass`).
"""

from __future__ import annotations

import numpy as np

from generator.geometry import Mesh, merge
from generator.geometry.primitives import polygon, prism
from generator.layout.network.grid import Grid
from generator.layout.network.measures import APRON_H_M

SIDES = 48             #: polygon sides of the island
KERB_BAND_M = 0.3      #: concrete band round the grass top


def island_mesh(grid: Grid) -> Mesh:
    """The island of a roundabout in the node frame (origin at the node centre), metres."""
    ring = grid.ring
    a = np.linspace(0.0, 2 * np.pi, SIDES, endpoint=False)
    circle = np.stack([np.cos(a), np.sin(a)], 1)
    parts = [prism(ring.island_r * circle, 0.0, APRON_H_M, "other_ground", "curb_concrete")]
    if ring.core_r > 0:
        parts.append(prism(ring.core_r * circle, APRON_H_M, grid.curb_h, "other_ground", "curb_concrete"))
    if ring.grass:
        top = np.c_[(ring.core_r - KERB_BAND_M) * circle, np.full(SIDES, grid.curb_h + 0.003)]
        parts.append(polygon(top, "terrain", "grass", normal=(0.0, 0.0, 1.0)))
    return merge(parts)
