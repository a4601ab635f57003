"""The terrain round the built area: the margin ring, and flat ground beyond it to the horizon.

Beyond the built area and the terrain margin the ground continues as flat grass at lot
height to a regular ``HORIZON_SIDES``-gon whose edges lie :data:`HORIZON_M` beyond the far
corner of the town bounds, so from anywhere in town the ground reaches the camera's far clip
distance in every direction: the horizon band under the sky stays ground, not void.
"""

from __future__ import annotations

import numpy as np

from generator.geometry import Mesh
from generator.labels import class_table
from generator.layout.ground.surfaces import rects
from generator.layout.network.grid import Grid
from generator.materials import material_table

HORIZON_M = 2000.0     #: ground reaches this far beyond the town bounds (Blender's camera clip_end)
HORIZON_SIDES = 12     #: sides of the polygon bounding the ground (a 12-gon: 16 triangles)


def margin_mesh(grid: Grid) -> Mesh:
    """The terrain ring between the built area and the town bounds (world frame)."""
    (bx0, by0), (bx1, by1) = grid.bounds
    ix0, iy0, ix1, iy1 = grid.built_rect
    ring = [(bx0, by0, bx1, iy0), (bx0, iy1, bx1, by1), (bx0, iy0, ix0, iy1), (ix1, iy0, bx1, iy1)]
    return rects(ring, grid.curb_h, "terrain", "grass")


def _zipper(inner: np.ndarray, outer: np.ndarray) -> np.ndarray:
    """(n + m, 3) int64 triangles joining two loops around the origin (indices: inner first).

    Both loops must be star-shaped about the origin and the outer one far outside the inner
    one; each is walked counter-clockwise by angle, always advancing the loop whose next
    vertex comes first. Every triangle is returned counter-clockwise seen from above.
    """
    n, m = len(inner), len(outer)
    ang_o = np.arctan2(outer[:, 1], outer[:, 0])
    start = ang_o.min()                          # both walks start at the first outer vertex's angle
    ang_i = np.mod(np.arctan2(inner[:, 1], inner[:, 0]) - start, 2 * np.pi)
    ang_o = np.mod(ang_o - start, 2 * np.pi)
    oi, oo = np.argsort(ang_i, kind="stable"), np.argsort(ang_o, kind="stable")
    ai = np.r_[ang_i[oi], ang_i[oi[0]] + 2 * np.pi]
    ao = np.r_[ang_o[oo], ang_o[oo[0]] + 2 * np.pi]
    idx_i = lambda k: int(oi[k % n])            # noqa: E731
    idx_o = lambda k: n + int(oo[k % m])        # noqa: E731
    tris, i, j = [], 0, 0
    while i < n or j < m:
        if j == m or (i < n and ai[i + 1] <= ao[j + 1]):
            tris.append((idx_i(i), idx_i(i + 1), idx_o(j)))
            i += 1
        else:
            tris.append((idx_i(i), idx_o(j), idx_o(j + 1)))
            j += 1
    f = np.array(tris, np.int64)
    pts = np.vstack([inner, outer])
    a, b, c = pts[f[:, 0]], pts[f[:, 1]], pts[f[:, 2]]
    cw = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]) < 0
    f[cw] = f[cw][:, [0, 2, 1]]
    return f


def horizon_radius(grid: Grid) -> float:
    """Circumradius (metres from the world origin) of the polygon the ground ends at."""
    reach = float(np.hypot(*np.abs(grid.bounds).max(0)))     # the far corner of the bounds
    return (reach + HORIZON_M) / float(np.cos(np.pi / HORIZON_SIDES))


def horizon_mesh(grid: Grid) -> Mesh:
    """Flat grass (class terrain) at lot height from the town bounds out to the horizon polygon.

    World frame; ``HORIZON_SIDES + 4`` triangles, all facing up.
    """
    (bx0, by0), (bx1, by1) = grid.bounds
    inner = np.array([(bx0, by0), (bx1, by0), (bx1, by1), (bx0, by1)], np.float64)
    t = 2 * np.pi * np.arange(HORIZON_SIDES) / HORIZON_SIDES
    outer = horizon_radius(grid) * np.stack([np.cos(t), np.sin(t)], 1)
    xy = np.vstack([inner, outer])
    v = np.c_[xy, np.full(len(xy), grid.curb_h)]
    return Mesh(v, _zipper(inner, outer), class_table().id("terrain"), material_table().id("grass"))
