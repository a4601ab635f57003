"""The city beyond the town (issue 29 item 6): low-detail blocks, tree lines and a skyline.

The town's ground runs flat to the horizon polygon (:mod:`generator.layout.ground.terrain`), which
from a street showed a green plane meeting the sky. This module fills the ground ring round the
town with a low-detail city, so the view out of town ends in more town:

* a tree line ``TREE_LINE_M`` beyond the town bounds, a tree every ~4 m round the whole town (closer
  than a crown is wide, so the crowns merge into one canopy band): a trunk (class tree_trunk,
  material ``bark``) under a crown of ``LOBES`` overlapping rounded low-poly lobes of mixed sizes at
  staggered heights (class vegetation, material ``leaves``; 30 triangles each), so the line reads as
  a belt of trees with a ragged top rather than a row of lollipops;
* city blocks from ``BLOCKS_FROM_M`` to ``REACH_M`` beyond the bounds on a square ``PITCH_M`` grid
  (streets left as open ground): each a park of a few crowns, or 1 to 4 buildings (class building),
  boxes whose walls are ``far_facade`` (a window pattern, windows lit at night) under a flat
  ``roof``, some with a smaller plant room on top (a roof line);
* building heights rise with distance: 9-24 m near the town, a skyline of 35-120 m towers beyond
  ``SKYLINE_M``, and round the ring's far edge a gapless band of 30-95 m towers, so no street of the
  block grid opens onto the bare horizon.

Twelve objects in all (made here in the world frame; the scene places each at its footprint's
centre, :func:`generator.layout.assemble.build_scene`): the tree line's four sides, the blocks and
parks of the ring's four sides (south, north, west, east: rectangles of whole rows and columns of
the block grid that meet neither each other, the tree line nor the town), and the far edge's four
sides. Every Blender object costs the RGB and label passes (Cycles syncs and instances each), and
a scene of one object per block held ~870 more of them; joined, the far city adds a dozen and keeps
every triangle, class and material (each building stays its own mesh island for the facade
shader). Blender and the LiDAR (which reaches 120 m and rarely meets it) share the same few
triangles: about 113 k round a default town (which has about 1.9 M). The draws come from the stream
``("layout", "far_city")`` only, so the town's own draws are untouched, and nothing stands within
``TREE_LINE_M - 2 - CROWN_R_M[1]`` (7 m) of the town bounds.
"""

from __future__ import annotations

import numpy as np

from generator.geometry import Mesh, merge
from generator.labels import class_table
from generator.materials import material_table
from generator.rng import stream

TREE_LINE_M = 14.0            #: distance of the tree line's centres beyond the town bounds
TREE_SPACING_M = 8.0          #: mean spacing of the tree line's crowns
CORNER_GAP_M = 12.0           #: the tree line's east and west sides stop this short of the corners
CROWN_R_M = (3.0, 5.0)        #: crown radius range
CROWN_H_M = (8.0, 14.0)       #: crown top height range
#: crown shape: (share of the height, share of the radius) of each ring, bottom up
CROWN_RINGS = ((0.06, 0.55), (0.38, 1.0), (0.74, 0.78))
CROWN_SIDES = 5               #: vertices per ring
LOBES = 6                     #: lobes of a tree line crown: the main one and five round it
CROWN_BASE = 0.22             #: a tree line crown starts at this share of the tree's height (the trunk below)
TRUNK_R_M = (0.16, 0.3)       #: tree line trunk radius range
TRUNK_SIDES = 6               #: sides of a trunk prism
BLOCKS_FROM_M = 40.0          #: the first block begins this far beyond the bounds
REACH_M = 1200.0              #: the last block ends within this distance of the bounds
PITCH_M, STREET_M = 90.0, 22.0  #: block grid pitch and the open street between blocks
PARK_SHARE = 0.12             #: share of blocks that are parks
SKYLINE_M = 550.0             #: beyond this distance from the bounds, towers appear
TOWER_SHARE = 0.35            #: share of the blocks beyond SKYLINE_M that hold one tower
LOW_H_M, TOWER_H_M = (9.0, 24.0), (35.0, 120.0)
WALL_DEPTH_M, WALL_H_M = 35.0, (30.0, 95.0)  #: the gapless band of towers at the ring's far edge
SIDE_GAP_M = 2.0             #: the band's west and east sides stop this short of the south and north sides

#: Unit box: 8 corners (x, y, z in {0, 1}) and its 10 triangles without the bottom (walls, then roof).
_BOX_V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)
_BOX_F = np.array([[0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5], [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7],
                   [4, 5, 6], [4, 6, 7]], np.int64)
_WALLS = 8


def _boxes(b: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Vertices, faces and roof flags of ``b`` (k, 6) boxes ``(x0, y0, z0, x1, y1, z1)``, no bottoms."""
    lo, hi = b[:, None, :3], b[:, None, 3:]
    v = (lo + _BOX_V[None] * (hi - lo)).reshape(-1, 3)
    f = (_BOX_F[None] + 8 * np.arange(len(b))[:, None, None]).reshape(-1, 3)
    roof = np.tile(np.arange(len(_BOX_F)) >= _WALLS, len(b))
    return v, f, roof


def _crowns(xy: np.ndarray, r: np.ndarray, h: np.ndarray, z0) -> tuple[np.ndarray, np.ndarray]:
    """Rounded low-poly crowns, 30 triangles each: a pentagon ring per ``CROWN_RINGS`` row (each turned
    half a step from the one below, so the bands between are antiprisms), capped by a centre
    vertex at the crown's base ``z0`` (a float, or (k,) per crown) and an apex ``h`` above; closed,
    faces outward. Shaded smooth (material ``leaves``), they read as round crowns rather than the
    spinning tops of a double cone.

    Returns
    -------
    v : (k * 17, 3) float64
    f : (k * 30, 3) int64
    """
    n, k, rows = CROWN_SIDES, len(xy), len(CROWN_RINGS)
    z0 = np.broadcast_to(np.asarray(z0, np.float64), (k,))
    rings = []
    for i, (zs, rs) in enumerate(CROWN_RINGS):
        a = 2 * np.pi * (np.arange(n) + 0.5 * i) / n
        ring = np.stack([np.cos(a), np.sin(a)], 1)                                # (n, 2)
        mid = xy[:, None, :] + rs * r[:, None, None] * ring[None]                 # (k, n, 2)
        rings.append(np.concatenate([mid, z0[:, None, None] + zs * h[:, None, None] + np.zeros((k, n, 1))], 2))
    v = np.concatenate([np.c_[xy, z0][:, None], *rings, np.c_[xy, z0 + h][:, None]], 1)
    nv = 2 + n * rows
    i = np.arange(n)
    j = (i + 1) % n
    faces = [np.stack([np.zeros(n, np.int64), 1 + j, 1 + i], 1)]                  # bottom cap, facing down
    for b in range(rows - 1):
        lo, hi = 1 + b * n, 1 + (b + 1) * n
        faces += [np.stack([lo + i, lo + j, hi + i], 1), np.stack([lo + j, hi + j, hi + i], 1)]
    top = 1 + (rows - 1) * n
    faces.append(np.stack([np.full(n, nv - 1), top + i, top + j], 1))               # top cap, facing up
    f = (np.concatenate(faces)[None] + nv * np.arange(k)[:, None, None]).reshape(-1, 3)
    return v.reshape(-1, 3), f


def _ring_cells(bounds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The block rectangles of the grid in the ring round ``bounds`` and the side each belongs to.

    Returns
    -------
    cells : (n, 4) float64
        ``(x0, y0, x1, y1)`` per block, rows of the grid in order, metres.
    side : (n,) int64
        0 south, 1 north, 2 west, 3 east: whole rows of blocks below the town's ``BLOCKS_FROM_M``
        line are south, whole rows above it north, the blocks of the rows between (beside the
        town) west or east. Each side's blocks lie in a rectangle that meets no other side's, the
        tree line or the town (the rows between begin a street above the last south row), so a
        side joined into one object has a footprint (even its convex hull) that touches nothing.
    """
    (bx0, by0), (bx1, by1) = bounds
    c = np.array([(bx0 + bx1) / 2, (by0 + by1) / 2])
    half = np.array([(bx1 - bx0) / 2, (by1 - by0) / 2])
    n = int(np.ceil((max(half) + REACH_M) / PITCH_M))
    k = np.arange(-n, n)
    gx, gy = np.meshgrid(k, k, indexing="ij")
    x0 = c[0] + gx.ravel() * PITCH_M + STREET_M / 2
    y0 = c[1] + gy.ravel() * PITCH_M + STREET_M / 2
    x1, y1 = x0 + PITCH_M - STREET_M, y0 + PITCH_M - STREET_M
    # distance of each rectangle from the bounds (0 if they overlap), and its far corner's
    gap = np.maximum(np.maximum(bx0 - x1, x0 - bx1), np.maximum(by0 - y1, y0 - by1))
    far = np.maximum(np.maximum(bx0 - x0, x1 - bx1), np.maximum(by0 - y0, y1 - by1))
    keep = (gap >= BLOCKS_FROM_M) & (far <= REACH_M)
    side = np.select([by0 - y1 >= BLOCKS_FROM_M, y0 - by1 >= BLOCKS_FROM_M, bx0 - x1 >= BLOCKS_FROM_M], [0, 1, 2], 3)
    return np.stack([x0, y0, x1, y1], 1)[keep], side[keep]


def _distance(bounds: np.ndarray, xy: np.ndarray) -> np.ndarray:
    """(k,) distance (m) of points from the bounds rectangle (the Chebyshev gap: the ring's own measure)."""
    (bx0, by0), (bx1, by1) = bounds
    return np.maximum(np.maximum(bx0 - xy[:, 0], xy[:, 0] - bx1), np.maximum(by0 - xy[:, 1], xy[:, 1] - by1))


def far_city(seed: int, bounds: np.ndarray, z0: float) -> list[tuple[str, str, Mesh]]:
    """The blocks, parks and tree lines round a town, world frame, as ``(kind, class, mesh)``.

    Parameters
    ----------
    seed : int
        The spec's seed; draws come from ``stream(seed, "layout", "far_city")`` (and the tree
        line's trunks and lobes from ``stream(seed, "layout", "far_city", "tree_line")``).
    bounds : (2, 2) float64
        The town's bounds ``[[xmin, ymin], [xmax, ymax]]``, metres.
    z0 : float
        Ground height there (the horizon ground's, ``curb_h``), metres.

    Returns
    -------
    list of (kind, cls, Mesh)
        ``("far_trees", "vegetation", ...)`` per side of the tree line (trunks of class tree_trunk,
        material ``bark``, under crowns of class vegetation, material ``leaves``), then
        ``("far_blocks", "building", ...)`` per side of the ring that holds blocks (buildings of class
        building, walls ``far_facade`` and roofs ``roof``; parks' crowns of class vegetation, material
        ``leaves``), then ``("far_skyline", "building", ...)`` per side
        of the far edge. No two of these meshes' footprints (nor their convex hulls or bounding
        boxes) overlap, and none encloses the town.
    """
    rng = stream(seed, "layout", "far_city")
    shape = stream(seed, "layout", "far_city", "tree_line")
    bounds = np.asarray(bounds, np.float64)
    (bx0, by0), (bx1, by1) = bounds
    out = []
    # the tree line: crowns along the rectangle TREE_LINE_M outside the bounds, jittered; the south
    # and north sides run through the corners, the east and west sides stop CORNER_GAP_M short of
    # them, so no two sides' crowns (nor boxes) meet
    t = TREE_LINE_M
    corners = np.array([(bx0 - t, by0 - t), (bx1 + t, by0 - t), (bx1 + t, by1 + t), (bx0 - t, by1 + t)])
    for k, (a, b) in enumerate(zip(corners, np.roll(corners, -1, 0), strict=True)):
        length = float(np.linalg.norm(b - a))
        u = (b - a) / length
        cut = CORNER_GAP_M * (k % 2)                                             # 0 south, north
        n = max(int((length - 2 * cut) // TREE_SPACING_M), 1)
        s = cut + (np.arange(n) + 0.5 + rng.uniform(-0.3, 0.3, n)) * (length - 2 * cut) / n
        out_dir = np.array([u[1], -u[0]])                                        # away from the town
        xy = a + s[:, None] * u + out_dir * rng.uniform(-2.0, 6.0, n)[:, None]
        out.append(("far_trees", "vegetation", _tree_mesh(rng, shape, xy, z0)))
    cells, sides = _ring_cells(bounds)
    parts: list[list[Mesh]] = [[] for _ in range(4)]
    for (x0, y0, x1, y1), side in zip(cells, sides, strict=True):
        d = float(_distance(bounds, np.array([[(x0 + x1) / 2, (y0 + y1) / 2]]))[0])
        if rng.uniform() < PARK_SHARE:
            m = int(rng.integers(3, 7))
            xy = np.stack([rng.uniform(x0 + 6, x1 - 6, m), rng.uniform(y0 + 6, y1 - 6, m)], 1)
            parts[side].append(_crown_mesh(rng, xy, z0))
            continue
        blocks = []
        if d > SKYLINE_M and rng.uniform() < TOWER_SHARE:
            w = rng.uniform(20.0, 34.0, 2)
            cx, cy = rng.uniform(x0 + w[0] / 2, x1 - w[0] / 2), rng.uniform(y0 + w[1] / 2, y1 - w[1] / 2)
            h = rng.uniform(*TOWER_H_M)
            blocks.append((cx - w[0] / 2, cy - w[1] / 2, z0, cx + w[0] / 2, cy + w[1] / 2, z0 + h))
        else:
            nx, ny = int(rng.integers(1, 3)), int(rng.integers(1, 3))
            xs, ys = np.linspace(x0, x1, nx + 1), np.linspace(y0, y1, ny + 1)
            for i in range(nx):
                for j in range(ny):
                    g = rng.uniform(0.0, 3.0, 4)                                 # gaps and setbacks
                    h = rng.uniform(*LOW_H_M) * (1.0 + 0.6 * min(d / SKYLINE_M, 1.0))
                    blocks.append((xs[i] + g[0], ys[j] + g[1], z0, xs[i + 1] - g[2], ys[j + 1] - g[3], z0 + h))
        parts[side].append(_block_mesh(rng, np.array(blocks, np.float64)))
    out += [("far_blocks", "building", merge(p)) for p in parts if p]
    # the skyline's far edge: a gapless wall of towers round the ring, so no street between the blocks
    # leads the eye to the bare horizon (one object per side; the south and north sides span the
    # corners, the west and east sides keep SIDE_GAP_M from them, so no two sides' boxes touch: a
    # slit 35 m deep that no line of sight from the town crosses)
    e, g = REACH_M + 10.0, SIDE_GAP_M
    sides = [((bx0 - e - WALL_DEPTH_M, by0 - e - WALL_DEPTH_M), (bx1 + e + WALL_DEPTH_M, by0 - e), 0),
             ((bx0 - e - WALL_DEPTH_M, by1 + e), (bx1 + e + WALL_DEPTH_M, by1 + e + WALL_DEPTH_M), 0),
             ((bx0 - e - WALL_DEPTH_M, by0 - e + g), (bx0 - e, by1 + e - g), 1),
             ((bx1 + e, by0 - e + g), (bx1 + e + WALL_DEPTH_M, by1 + e - g), 1)]
    for (x0, y0), (x1, y1), axis in sides:
        a0, a1 = (x0, x1) if axis == 0 else (y0, y1)
        cuts = [a0]
        while cuts[-1] < a1:
            cuts.append(min(cuts[-1] + rng.uniform(25.0, 60.0), a1))
        cuts = np.array(cuts)
        h = z0 + rng.uniform(*WALL_H_M, len(cuts) - 1)
        if axis == 0:
            b = np.stack([cuts[:-1], np.full_like(h, y0), np.full_like(h, z0), cuts[1:], np.full_like(h, y1), h], 1)
        else:
            b = np.stack([np.full_like(h, x0), cuts[:-1], np.full_like(h, z0), np.full_like(h, x1), cuts[1:], h], 1)
        out.append(("far_skyline", "building", _block_mesh(rng, b)))
    return out


def _block_mesh(rng: np.random.Generator, b: np.ndarray) -> Mesh:
    """Buildings ``b`` (k, 6), 40 % of them with a plant room on the roof (a roof line)."""
    top = rng.uniform(size=len(b)) < 0.4
    inset = np.minimum(b[top, 3] - b[top, 0], b[top, 4] - b[top, 1])[:, None] * np.array([0.3, 0.3])
    rooms = np.c_[b[top, :2] + inset, b[top, 5], b[top, 3:5] - inset, b[top, 5] + rng.uniform(2.5, 4.5, top.sum())]
    v, f, roof = _boxes(np.vstack([b, rooms]))
    mats = material_table()
    return Mesh(v, f, class_table().id("building"), np.where(roof, mats.id("roof"), mats.id("far_facade")))


def _crown_mesh(rng: np.random.Generator, xy: np.ndarray, z0: float) -> Mesh:
    v, f = _crowns(xy, rng.uniform(*CROWN_R_M, len(xy)), rng.uniform(*CROWN_H_M, len(xy)), z0)
    return Mesh(v, f, class_table().id("vegetation"), material_table().id("leaves"))


def _prisms(xy: np.ndarray, r: np.ndarray, z0: float, z1: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Open ``TRUNK_SIDES``-sided prisms (no caps: their ends are in the ground and the crown), faces outward.

    Returns
    -------
    v : (k * 2 * TRUNK_SIDES, 3) float64
    f : (k * 2 * TRUNK_SIDES, 3) int64
    """
    n, k = TRUNK_SIDES, len(xy)
    a = 2 * np.pi * np.arange(n) / n
    ring = xy[:, None, :] + r[:, None, None] * np.stack([np.cos(a), np.sin(a)], 1)[None]          # (k, n, 2)
    lo = np.concatenate([ring, np.full((k, n, 1), z0)], 2)
    hi = np.concatenate([ring, np.broadcast_to(z1[:, None, None], (k, n, 1))], 2)
    v = np.concatenate([lo, hi], 1)                                                           # (k, 2n, 3)
    i = np.arange(n)
    j = (i + 1) % n
    f = np.concatenate([np.stack([i, j, n + j], 1), np.stack([i, n + j, n + i], 1)])
    return v.reshape(-1, 3), (f[None] + 2 * n * np.arange(k)[:, None, None]).reshape(-1, 3)


def _tree_mesh(rng: np.random.Generator, shape: np.random.Generator, xy: np.ndarray, z0: float) -> Mesh:
    """Trees of the tree line at ``xy`` (k, 2), and one more between each two neighbours.

    Each is a trunk up into a crown of ``LOBES`` lobes. The main lobe spans ``CROWN_BASE`` of the
    tree's height to its top; each other lobe, turned a random way and pushed out by up to 0.4 of the
    crown radius, is smaller (0.4-0.6 of the crown) and starts anywhere in the crown's lower half,
    so crowns differ in outline and each lobe (a mesh island) takes its own shade of the ``leaves``
    material. The trees at ``xy`` take their crown radius and height from ``rng`` (as the single
    crowns of parks draw theirs); the trees between them (somewhere in the middle third of the gap,
    heights 0.7-1.3x of their neighbours' mean), the trunks and the lobes come from ``shape``, so the
    rest of the far city draws what it drew before. No lobe reaches further than the crown radius
    from its trunk.
    """
    k = len(xy)
    r, h = rng.uniform(*CROWN_R_M, k), rng.uniform(*CROWN_H_M, k)
    if k > 1:
        t = shape.uniform(0.35, 0.65, k - 1)[:, None]
        xy = np.concatenate([xy, xy[:-1] + t * (xy[1:] - xy[:-1])])
        r = np.concatenate([r, shape.uniform(0.8, 1.0, k - 1) * (r[:-1] + r[1:]) / 2])
        h = np.concatenate([h, shape.uniform(0.7, 1.3, k - 1) * (h[:-1] + h[1:]) / 2])
        k = len(xy)
    base = z0 + CROWN_BASE * h
    ch = (1.0 - CROWN_BASE) * h                                                  # crown height
    classes, mats = class_table(), material_table()
    parts = [Mesh(*_prisms(xy, shape.uniform(*TRUNK_R_M, k), z0, base + 0.3 * ch), classes.id("tree_trunk"),
                  mats.id("bark")),
             Mesh(*_crowns(xy, 0.8 * r, ch, base), classes.id("vegetation"), mats.id("leaves"))]
    for _ in range(LOBES - 1):   # a lobe reaches at most 0.4 r + 0.6 r from the trunk: the 7 m gap holds
        a = shape.uniform(0, 2 * np.pi, k)
        d = shape.uniform(0.2, 0.4, k)[:, None] * r[:, None] * np.stack([np.cos(a), np.sin(a)], 1)
        s = shape.uniform(0.4, 0.6, k)
        parts.append(Mesh(*_crowns(xy + d, s * r, s * ch, base + shape.uniform(0.0, 0.5, k) * ch),
                          classes.id("vegetation"), mats.id("leaves")))
    return merge(parts)
