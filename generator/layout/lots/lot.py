"""Blocks split into lots: building plans, parks, yards, hedges and fences along the fronts.

Each block (inside its sidewalks) is cut into one or two rows of lots; each row faces one
street and is cut along its frontage into 2-6 lots of varied width (corner lots face the
row's street). The band of lots outside the outer ring road
(:func:`generator.layout.lots.outskirts.outer_rows`) is planned the same way. A lot has its own
frame: ``a`` along the frontage, ``b`` into the lot (b = 0 at
the sidewalk's outer edge), z up; its yaw is chosen so that this frame is exactly the local
frame of a building asset (front towards -y = towards the street).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from generator.geometry import Mesh, merge, pose
from generator.layout.ground.surfaces import rects
from generator.layout.lots.districts import DISTRICTS, District, draw_districts
from generator.layout.lots.outskirts import outer_rows
from generator.layout.network.grid import Grid
from generator.rng import stream
from generator.spec.model import SceneSpec

MIN_LOT_W = 9.0        #: narrowest lot along the frontage, metres
MIN_ROW_DEPTH = 14.0   #: a block is split into two rows only if each gets at least this depth
SIDE_GAP = (1.2, 3.0)  #: building to lot side, metres
BACK_GAP = 2.0         #: building to lot back, metres
FRONT_GAP_M = 2.0      #: gap left in a hedge or fence for the entrance
FRONT_B = 0.6          #: centre line of hedges/fences, metres behind the lot front
FACADES = ("plaster", "brick", "concrete")
GLASS_SHARE = 0.15     #: share of buildings of 5+ storeys that are glass curtain walls
#: render (plaster) colours a building is painted in: cream, ochre, salmon, sage, blue-grey,
#: off-white, terracotta, yellow (multiplied into the plaster shader)
RENDER_COLOURS = ((0.86, 0.80, 0.66), (0.80, 0.62, 0.38), (0.82, 0.58, 0.50), (0.66, 0.74, 0.60),
                  (0.62, 0.68, 0.74), (0.88, 0.86, 0.82), (0.72, 0.45, 0.34), (0.86, 0.76, 0.45))
ROOFS = ("flat", "gable", "hip")


@dataclass
class BuildingPlan:
    """A building on a lot, in the lot frame.

    Attributes
    ----------
    footprint : (k, 2) float64
        Counter-clockwise polygon in the building's local frame (bounding box centred on 0).
    center : (2,) float
        Footprint bounding-box centre in the lot frame (a, b), metres.
    height, floor_height : float
        Metres; the height is a whole number of floors.
    facade, roof : str
        Asset parameters (``plaster|brick|concrete``, ``flat|gable|hip``).
    attrs : dict
        Render tints: ``facade_color``, ``roof_color`` (3 floats in 0..1).
    """

    footprint: np.ndarray
    center: tuple[float, float]
    height: float
    floor_height: float
    facade: str
    roof: str
    attrs: dict


@dataclass
class FrontLine:
    """A hedge or fence piece along the lot front: ``a0..a1`` at ``b`` (lot frame, metres).

    ``across`` pieces run along the lot's depth instead (a lot side on a street): ``b`` from
    ``a0`` to ``a1`` at ``a = b``.
    """

    kind: str        # "hedge" | "fence"
    a0: float
    a1: float
    b: float
    across: bool = False


@dataclass
class Lot:
    """One lot of a block (see the module docstring for its frame)."""

    index: int
    block: tuple[int, int]            #: block (i, j), or (-1, side) outside the ring road (side 0..3: S, E, N, W)
    origin: tuple[float, float]       #: world xy of the front centre, metres
    yaw: float                        #: radians; lot (a, b) axes = building local (x, y)
    width: float
    depth: float
    use: str                          #: "building" | "park" | "yard"
    ground: str                       #: "grass" | "paving"
    building: BuildingPlan | None = None
    front: list[FrontLine] = field(default_factory=list)
    entrance_a: float = 0.0           #: a of the door / gate (lot frame)
    district: str = ""                #: its block's district ("" without a streets spec)
    front_height: float | None = None  #: hedge/fence height the district drew (None: place_fronts draws it)
    greenery: float = 1.0             #: multiplier on the lot's trees and bushes

    def transform(self, z: float = 0.0) -> np.ndarray:
        """(4, 4) world-from-lot transform."""
        return pose(self.origin[0], self.origin[1], z, self.yaw)

    def to_world(self, ab: np.ndarray) -> np.ndarray:
        """(n, 2) world xy of lot-frame points ``ab`` ((n, 2) metres)."""
        ab = np.asarray(ab, np.float64).reshape(-1, 2)
        c, s = np.cos(self.yaw), np.sin(self.yaw)
        return np.stack([ab[:, 0] * c - ab[:, 1] * s, ab[:, 0] * s + ab[:, 1] * c], 1) + np.asarray(self.origin)

    def corners_world(self) -> np.ndarray:
        """(4, 2) world corners of the lot."""
        w = self.width / 2
        return self.to_world([(-w, 0), (w, 0), (w, self.depth), (-w, self.depth)])


def _rows(rect: tuple[float, float, float, float], g: np.random.Generator):
    """Rows of a block: (origin of the row's front-left corner, unit a, unit b (into lot), frontage, depth)."""
    x0, y0, x1, y1 = rect
    w, d = x1 - x0, y1 - y0
    along_x = w >= d if abs(w - d) > 4 else bool(g.random() < 0.5)
    depth = d if along_x else w
    # faces: (front-left corner, a axis, b axis); a x b = +z so the lot frame is right-handed
    if along_x:
        faces = [((x0, y0), (1, 0), (0, 1), w), ((x1, y1), (-1, 0), (0, -1), w)]
    else:
        faces = [((x0, y1), (0, -1), (1, 0), d), ((x1, y0), (0, 1), (-1, 0), d)]
    if depth >= 2 * MIN_ROW_DEPTH:
        split = depth / 2 + g.uniform(-0.1, 0.1) * depth
        return [(faces[0], split), (faces[1], depth - split)]
    return [(faces[int(g.integers(2))], depth)]


def _widths(frontage: float, g: np.random.Generator) -> np.ndarray:
    n = int(min(g.integers(2, 7), max(1, frontage // MIN_LOT_W)))
    w = g.uniform(0.65, 1.35, n)
    w = w / w.sum() * frontage
    # keep every lot at least MIN_LOT_W wide when the frontage allows it
    while n > 1 and w.min() < MIN_LOT_W:
        n -= 1
        w = np.full(n, frontage / n)
    return w


def _footprint(w: float, d: float, g: np.random.Generator) -> np.ndarray:
    hw, hd = w / 2, d / 2
    if w >= 10 and d >= 10 and g.random() < 0.35:
        nx, ny = w * g.uniform(0.35, 0.6), d * g.uniform(0.35, 0.55)
        p = np.array([(-hw, -hd), (hw, -hd), (hw, hd - ny), (hw - nx, hd - ny), (hw - nx, hd), (-hw, hd)])
        if g.random() < 0.5:       # notch at the back-left instead: mirror x and keep CCW
            p = (p * [-1, 1])[::-1]
        return p
    return np.array([(-hw, -hd), (hw, -hd), (hw, hd), (-hw, hd)])


def _building(spec: SceneSpec, width: float, depth: float, setback: float, g: np.random.Generator,
              district: District | None = None, look: np.random.Generator | None = None) -> BuildingPlan | None:
    """A building plan for a lot (shaped by its ``district`` when drawn); ``look`` (the lot's own stream)
    draws the curtain walls and the render colours, so those draws do not shift the plans of the lots after it."""
    side = g.uniform(*SIDE_GAP, 2)
    bw = width - side.sum()
    bd = min(g.uniform(*(district.depth_m if district else (10.0, 22.0))), depth - setback - BACK_GAP)
    if bw < 6.0 or bd < 6.0:
        return None
    hf = spec.heights.floor_m
    lo, hi = district.height_m if district else spec.heights.building_m
    floors = max(1, int(round(g.uniform(lo, hi) / hf)))
    facade = FACADES[int(g.integers(len(FACADES)))]
    glass, colour = (look.random() < GLASS_SHARE, int(look.integers(len(RENDER_COLOURS)))) if look else (False, 0)
    if floors >= 5 and glass:      # some tall buildings are glass curtain walls
        facade = "glass"
    roof = "flat" if floors > 4 or g.random() < 0.35 else ROOFS[1 + int(g.integers(2))]
    base = {"plaster": RENDER_COLOURS[colour], "brick": (0.6, 0.32, 0.24), "concrete": (0.65, 0.65, 0.63),
            "glass": (0.8, 0.85, 0.9)}[facade]
    tint = np.clip(np.asarray(base) * g.uniform(0.85, 1.15, 3), 0, 1)
    roof_base = np.array((0.35, 0.28, 0.26) if roof != "flat" else (0.4, 0.4, 0.42))
    roof_tint = np.clip(roof_base * g.uniform(0.8, 1.2, 3), 0, 1)
    attrs = {"facade_color": [round(float(c), 4) for c in tint], "roof_color": [round(float(c), 4) for c in roof_tint]}
    center = (float(-width / 2 + side[0] + bw / 2), float(setback + bd / 2))
    return BuildingPlan(_footprint(bw, bd, g), center, floors * hf, hf, facade, roof, attrs)


def _front(kind: str, width: float, gap_at: float) -> list[FrontLine]:
    a0, a1 = -width / 2 + 0.4, width / 2 - 0.4
    g0, g1 = gap_at - FRONT_GAP_M / 2, gap_at + FRONT_GAP_M / 2
    return [FrontLine(kind, float(s), float(e), FRONT_B) for s, e in ((a0, g0), (g1, a1)) if e - s >= 1.0]


def make_lots(spec: SceneSpec, grid: Grid) -> list[Lot]:
    """Split every block, then the band outside the outer ring road, into lots and plan what
    stands on each (streams ``("layout", "lots")`` and ``("layout", "outer_lots")``)."""
    g = stream(spec.seed, "layout", "lots")
    d = spec.density
    lots: list[Lot] = []
    nx, ny = len(grid.xs) - 1, len(grid.ys) - 1
    sections = outer_rows(grid)
    districts = draw_districts(spec, nx * ny + len(sections), (nx * ny, len(sections)))

    def row(block, corner, ua, ub, widths, depth, g, district):
        yaw = float(np.arctan2(ub[1], ub[0]) - np.pi / 2)
        a = 0.0
        for w in widths:
            origin = np.asarray(corner) + np.asarray(ua) * (a + w / 2)
            a += w
            lot = _plan_lot(spec, len(lots), block, origin, yaw, float(w), float(depth), d, g, district)
            lots.append(lot)

    for j in range(ny):
        for i in range(nx):
            for (corner, ua, ub, frontage), depth in _rows(grid.block_rect(i, j), g):
                row((i, j), corner, ua, ub, _widths(frontage, g), depth, g, districts[j * nx + i])
    g = stream(spec.seed, "layout", "outer_lots")
    for k, (side, corner, ua, ub, frontage, is_corner) in enumerate(sections):
        row((-1, side), corner, ua, ub, [frontage] if is_corner else _widths(frontage, g), grid.outer_depth, g,
            districts[nx * ny + k])
    line_street_edges(lots, grid)
    return lots


def _plan_lot(spec, index, block, origin, yaw, width, depth, d, g, district: str = "") -> Lot:
    if district in DISTRICTS:
        return _plan_district_lot(spec, index, block, origin, yaw, width, depth, DISTRICTS[district], district, g)
    r = g.random()
    front = "hedge" if r < d.hedges else ("fence" if r < d.hedges + d.fences else None)
    lot = Lot(index, block, (float(origin[0]), float(origin[1])), yaw, width, depth, "yard", "grass")
    if g.random() < d.buildings:
        setback = g.uniform(2.5, 4.0) if front else g.uniform(0.0, 4.0)
        look = stream(spec.seed, "layout", "facade_look", index)
        lot.building = _building(spec, width, depth, float(setback), g, look=look)
    if lot.building is not None:
        lot.use = "building"
        lot.ground = "grass" if g.random() < 0.7 else "paving"
        lot.entrance_a = lot.building.center[0]
    else:
        lot.use = "park" if g.random() < d.parks else "yard"
        lot.entrance_a = float(g.uniform(-0.25, 0.25) * width)
        if lot.use == "park":
            front = None if g.random() < 0.5 else front
    if front:
        lot.front = _front(front, width, lot.entrance_a)
    lot.district = district
    return lot


def _plan_district_lot(spec, index, block, origin, yaw, width, depth, dist: District, name: str, g) -> Lot:
    """A lot planned by its district's parameters (see :mod:`generator.layout.lots.districts`)."""
    r = g.random()
    front = "hedge" if r < dist.hedge else ("fence" if r < dist.hedge + dist.fence else None)
    lot = Lot(index, block, (float(origin[0]), float(origin[1])), yaw, width, depth, "yard", "grass",
              district=name, front_height=float(g.uniform(*dist.front_height_m)), greenery=dist.greenery)
    if g.random() < dist.buildings:
        setback = max(float(g.uniform(*dist.setback_m)), 1.5 if front else 0.0)   # clear of the hedge
        lot.building = _building(spec, width, depth, setback, g, dist,
                                 look=stream(spec.seed, "layout", "facade_look", index))
    if lot.building is not None:
        lot.use = "building"
        lot.ground = "grass" if g.random() < dist.grass else "paving"
        lot.entrance_a = lot.building.center[0]
        lot.building.attrs["district"] = name
    else:
        lot.use = "park" if g.random() < dist.parks else "yard"
        lot.entrance_a = float(g.uniform(-0.25, 0.25) * width)
    if front:
        lot.front = _front(front, width, lot.entrance_a)
    return lot


def _street_edges(lot: Lot, rect: tuple[float, float, float, float]) -> list[FrontLine]:
    """Lines along the sides and back of a block lot that lie on its block's edge (a street), set
    ``FRONT_B`` inside the lot, of the same kind as its front (none if the front has none)."""
    if not lot.front:
        return []
    kind, w, d = lot.front[0].kind, lot.width / 2, lot.depth
    x0, y0, x1, y1 = rect

    def on_edge(p, q) -> bool:
        for k, lo, hi in ((0, x0, x1), (1, y0, y1)):
            for e in (lo, hi):
                if abs(p[k] - e) < 1e-6 and abs(q[k] - e) < 1e-6:
                    return True
        return False

    c = lot.corners_world()         # front-left, front-right, back-right, back-left
    out = []
    if on_edge(c[1], c[2]):
        out.append(FrontLine(kind, FRONT_B + 0.5, d - 0.4, w - FRONT_B, True))
    if on_edge(c[3], c[0]):
        out.append(FrontLine(kind, FRONT_B + 0.5, d - 0.4, -w + FRONT_B, True))
    if on_edge(c[2], c[3]):
        out.append(FrontLine(kind, -w + 0.4, w - 0.4, d - FRONT_B))
    return [f for f in out if f.a1 - f.a0 >= 1.0]


def line_street_edges(lots: list[Lot], grid: Grid) -> None:
    """District lots inside blocks: hedge or fence also along the sides and back that face a street."""
    for lot in lots:
        if lot.district and lot.block[0] >= 0:
            lot.front += _street_edges(lot, grid.block_rect(*lot.block))


def lot_ground_mesh(lot: Lot, curb_h: float) -> Mesh:
    """Ground of ``lot`` at sidewalk height (lot frame), with a paved path to the entrance."""
    w = lot.width / 2
    cls, mat = ("terrain", "grass") if lot.ground == "grass" else ("sidewalk", "sidewalk_concrete")
    parts = [rects([(-w, 0, w, lot.depth)], curb_h, cls, mat)]
    if lot.building is not None and lot.ground == "grass":
        setback = lot.building.center[1] - np.ptp(lot.building.footprint[:, 1]) / 2
        if setback > 0.3:
            a = lot.entrance_a
            parts.append(rects([(a - 0.75, 0, a + 0.75, setback)], curb_h + 0.003, "sidewalk", "sidewalk_concrete"))
    return merge(parts)
